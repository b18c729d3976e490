"""Readers for the standard benchmark problem formats.

The Siconos text format is read by the Rust core (``coulomb._core``); see
``../shared/data/siconos-lcp/SOURCE.md`` for the layout (dense column-major and sparse-block
storage).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import _core

__all__ = ["LcpProblem", "read_siconos_lcp"]


@dataclass(frozen=True)
class LcpProblem:
    """An LCP ``0 <= z ⊥ M z + q >= 0`` read from a file."""

    M: NDArray[np.float64]
    q: NDArray[np.float64]
    name: str

    @property
    def n(self) -> int:
        """The problem size."""
        return int(self.q.shape[0])


def read_siconos_lcp(path: str | os.PathLike[str]) -> LcpProblem:
    """Read a Siconos LCP file (``lcp_*.dat``), dense or sparse-block storage.

    Raises ``FileNotFoundError`` for a missing file and
    :class:`coulomb.errors.ProblemFormatError` for a malformed one.
    """
    M, q = _core.read_siconos_lcp(os.fspath(path))
    return LcpProblem(M=M, q=q, name=os.path.splitext(os.path.basename(os.fspath(path)))[0])
