"""Readers for the standard benchmark problem formats.

The Siconos text format is read by the Rust core (``coulomb._core``); see
``../shared/data/siconos-lcp/SOURCE.md`` and ``../shared/data/siconos-fc/SOURCE.md`` for the
layout (dense column-major, sparse-block and CSparse storage).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import _core

__all__ = [
    "FrictionContactProblem",
    "GlobalFrictionContactProblem",
    "LcpProblem",
    "read_siconos_fc",
    "read_siconos_lcp",
]


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


def _name(path: str | os.PathLike[str]) -> str:
    return os.path.splitext(os.path.basename(os.fspath(path)))[0]


@dataclass(frozen=True)
class FrictionContactProblem:
    """A local friction-contact problem ``u = W r + q`` with Coulomb's law at each contact.

    ``W`` is dense ``(dim nc, dim nc)``, ``q`` has ``dim nc`` entries (contact by contact,
    normal first) and ``mu`` one per contact. Solve it with
    ``coulomb.contact.solve(p.W, p.q, p.mu, p.dim)``.
    """

    W: NDArray[np.float64]
    q: NDArray[np.float64]
    mu: NDArray[np.float64]
    dim: int
    name: str

    @property
    def nc(self) -> int:
        """The number of contacts."""
        return int(self.mu.shape[0])


@dataclass(frozen=True)
class GlobalFrictionContactProblem:
    """A global friction-contact problem: ``M v = q + H r``, ``u = H^T v + b``, with
    Coulomb's law between u and r at each contact. ``M`` and ``H`` are dense."""

    M: NDArray[np.float64]
    H: NDArray[np.float64]
    q: NDArray[np.float64]
    b: NDArray[np.float64]
    mu: NDArray[np.float64]
    dim: int
    name: str

    @property
    def nc(self) -> int:
        """The number of contacts."""
        return int(self.mu.shape[0])


def read_siconos_fc(
    path: str | os.PathLike[str],
) -> FrictionContactProblem | GlobalFrictionContactProblem:
    """Read a Siconos friction-contact file (``FC2D``/``FC3D`` local or ``GFC3D`` global).

    Matrices are densified whatever their storage on file (dense, sparse-block, CSparse);
    matrices beyond 5000 x 5000 raise :class:`coulomb.errors.ProblemTooLargeError`. Raises
    ``FileNotFoundError`` for a missing file and :class:`coulomb.errors.ProblemFormatError`
    for a malformed one.
    """
    d = _core.read_siconos_fc(os.fspath(path))
    if d["kind"] == "global":
        return GlobalFrictionContactProblem(
            M=d["M"], H=d["H"], q=d["q"], b=d["b"], mu=d["mu"], dim=int(d["dim"]), name=_name(path)
        )
    return FrictionContactProblem(
        W=d["W"], q=d["q"], mu=d["mu"], dim=int(d["dim"]), name=_name(path)
    )
