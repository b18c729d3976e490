"""Argument checks shared by scenes and user models (vectors, step counts, solver options)."""

from __future__ import annotations

import math
from typing import Any, Literal, cast

import numpy as np

from . import _validate
from .errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
    ShapeError,
)

Solver = Literal["nsgs", "lemke"]


#: integers a float holds exactly; larger ones take numpy's path and its messages
_EXACT_INT = 1 << 53


def _vector(name: str, value: Any, n: int) -> list[float]:
    if type(value) in (tuple, list) and len(value) == n:
        # a short tuple of Python numbers, the common case (a scene of 10^5 bodies checks
        # 10^6 of them): the same answer as numpy's path, without an array per vector
        out = []
        for x in value:
            t = type(x)
            if t is float and math.isfinite(x):
                out.append(x)
            elif t is int and -_EXACT_INT <= x <= _EXACT_INT:
                out.append(float(x))
            else:
                break
        else:
            return out
    if value is None:
        raise ArgumentTypeError(f"{name} must be {n} real numbers, got None")
    arr = _validate.array(value, name, None).reshape(-1)
    if arr.shape != (n,):
        raise ShapeError(f"{name} must have {n} entries, got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} has a non-finite entry: {arr.tolist()}")
    return arr.tolist()


def _positive(name: str, value: float) -> float:
    return _validate.real(name, value, low=0.0, low_open=True, data=True)


def _steps(t_end: float, h: float) -> int:
    """``ceil(t_end / h)``, at least 1, at most :data:`coulomb._validate.MAX_COUNT`."""
    ratio = t_end / h
    if not ratio <= _validate.MAX_COUNT:
        raise InvalidParameterError(
            f"t_end / h = {ratio:.3g} steps, more than the limit of {_validate.MAX_COUNT}: "
            "use a larger h or a shorter t_end"
        )
    return max(1, math.ceil(ratio - 1e-9))


def _solver_options(
    dim: int, solver: Any, tol: Any, max_iter: Any, relaxation: Any, facets: Any
) -> tuple[Solver, float, int | None, float, int | None]:
    """A simulation's contact-solver options, checked as :func:`coulomb.contact.solve` checks
    them (the same messages, the same refusals)."""
    _validate.choice("solver", solver, ("nsgs", "lemke"),
                     "'nsgs' exact friction disk, 'lemke' polyhedral cone")
    if tol is None:
        tol = 1e-12 if solver == "nsgs" else 1e-9
    _, t, it, om, fa, _ = _validate.contact_options(dim, solver, tol, max_iter, relaxation,
                                                    facets, None)
    if fa is not None and dim == 2 and fa != 2:
        raise InvalidParameterError(
            f"facets must be 2 in 2D (the tangent directions +1 and -1, which are exact), "
            f"got {fa}")
    if fa is not None and dim == 3 and (fa < 4 or fa % 2):
        raise InvalidParameterError(
            f"facets must be even and at least 4 in 3D (tangent directions in +/- pairs), "
            f"got {fa}")
    return cast(Solver, solver), t, it, om, fa


def _dim(dim: Any) -> None:
    if isinstance(dim, (bool, np.bool_)) or not isinstance(dim, (int, np.integer)) or int(
        dim
    ) not in (2, 3):
        raise InvalidParameterError(f"dim must be 2 (planar) or 3 (spatial), got {dim!r}")
