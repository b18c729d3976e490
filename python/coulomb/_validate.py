"""Argument checks shared by every public entry point.

Each check names the argument and what was expected, raises a :mod:`coulomb.errors` class
(the ``...TypeError`` ones are also ``TypeError``), and runs before any work. Counts are
Python or numpy ints only (not bools, floats or strings) within ``[minimum, MAX_COUNT]``;
reals are ints or floats (not bools, strings or None), finite unless said otherwise.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .errors import (
    ArgumentTypeError,
    InvalidInputError,
    InvalidParameterError,
    NonFiniteError,
    ShapeError,
)

__all__ = [
    "MAX_COUNT",
    "array",
    "boolean",
    "choice",
    "count",
    "optional_count",
    "real",
    "tolerance",
    "unused",
]

#: the largest iteration, pivot, sweep or step count any option takes (10^9): larger ones
#: would run for days; and every loop can be stopped by Ctrl-C anyway.
MAX_COUNT = 10**9

#: the most tangent directions of the polyhedral cone (``facets``): 1024 directions already
#: approximate the friction disk to a relative 5e-6.
MAX_FACETS = 1024

_F64 = np.dtype(np.float64)


def _is_real(v: object) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def _kind(value: object) -> str:
    return "None" if value is None else f"{type(value).__name__} {value!r}"


def count(name: str, value: Any, *, minimum: int = 1, maximum: int = MAX_COUNT) -> int:
    """An int (Python or numpy, not a bool) in ``[minimum, maximum]``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ArgumentTypeError(f"{name} must be an integer, got {_kind(value)}")
    v = int(value)
    if not minimum <= v <= maximum:
        raise InvalidParameterError(
            f"{name} must be an integer in [{minimum}, {maximum}], got {v}"
        )
    return v


def optional_count(
    name: str, value: Any, *, minimum: int = 1, maximum: int = MAX_COUNT
) -> int | None:
    """None, or :func:`count`."""
    return None if value is None else count(name, value, minimum=minimum, maximum=maximum)


def real(
    name: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    finite: bool = True,
    data: bool = False,
) -> float:
    """A real number (int or float, Python or numpy; not a bool, string, None or complex),
    finite unless ``finite=False``, within the bounds given (closed unless ``*_open``). A NaN
    or infinity raises :class:`NonFiniteError` for ``data=True`` (a physical value such as a
    mass or a time), :class:`InvalidParameterError` otherwise (an option such as ``tol``)."""
    if type(value) is float:
        # the common case, without the abstract-base-class checks (about 0.6 us a call, paid
        # several times by every solve and simulate)
        v = value
    else:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
            raise ArgumentTypeError(f"{name} must be a real number, got {_kind(value)}")
        try:
            v = float(value)
        except OverflowError:
            raise InvalidParameterError(f"{name} is too large for a float: {value}") from None
    if math.isnan(v) or (finite and math.isinf(v)):
        raise (NonFiniteError if data else InvalidParameterError)(
            f"{name} must be a finite number, got {v}"
        )
    lo_ok = low is None or (v > low if low_open else v >= low)
    hi_ok = high is None or (v < high if high_open else v <= high)
    if not (lo_ok and hi_ok):
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        left = "(" if low is None or low_open else "["
        right = ")" if high is None or high_open else "]"
        span = f"{left}{lo}, {hi}{right}"
        raise InvalidParameterError(f"{name} must lie in {span}, got {v:g}")
    return v


def tolerance(name: str, value: Any) -> float:
    """A relative tolerance: a real number in (0, 1). A tolerance of 1 or more would call any
    answer (z = 0 among them) a solution."""
    return real(name, value, low=0.0, high=1.0, low_open=True, high_open=True)


def boolean(name: str, value: Any) -> bool:
    """True or False (Python or numpy bool)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ArgumentTypeError(f"{name} must be True or False, got {_kind(value)}")
    return bool(value)


def choice(name: str, value: Any, options: Sequence[str], what: str = "") -> str:
    """One of the strings ``options``."""
    if not isinstance(value, str) or value not in options:
        raise InvalidParameterError(
            f"{name} must be one of {', '.join(repr(o) for o in options)}"
            f"{' (' + what + ')' if what else ''}, got {value!r}"
        )
    return value


def unused(method_name: str, method: str, **given: Any) -> None:
    """Refuses options that ``method`` does not use (given as name=value, None meaning not
    given)."""
    for opt, value in given.items():
        if value is not None:
            raise InvalidParameterError(
                f"{opt} does not apply to {method_name}={method!r}; leave it out"
            )


def array(x: Any, name: str, ndim: int | None) -> NDArray[np.float64]:
    """A float64, C-contiguous array of ``ndim`` dimensions (no copy when it already is one),
    refusing None, ragged nested lists, strings, objects, complex numbers and wrong
    dimensions with a message naming the argument (``ndim=None``: any dimension). NaN and
    infinity pass (checked where the data are used, with their position)."""
    if (
        type(x) is np.ndarray
        and x.dtype == _F64
        and x.ndim == ndim
        and x.flags.c_contiguous
    ):
        return x
    if x is None:
        raise ArgumentTypeError(f"{name} must be an array of real numbers, got None")
    if isinstance(x, (str, bytes)):
        raise ArgumentTypeError(f"{name} must be an array of real numbers, got a string")
    if hasattr(x, "toarray") and callable(x.toarray):  # scipy.sparse
        x = x.toarray()
    try:
        raw = np.asarray(x)
    except ValueError:
        raise ShapeError(
            f"{name} must be a rectangular array of real numbers; got nested "
            "sequences of unequal lengths"
        ) from None
    kind = raw.dtype.kind
    if kind == "c":
        raise InvalidInputError(f"{name} must be real, got a complex array")
    if kind == "O":
        bad = [v for v in raw.reshape(-1) if not _is_real(v)]
        if bad or not raw.size:
            raise ArgumentTypeError(
                f"{name} must be an array of real numbers, got an entry {_kind(bad[0])}"
                if bad
                else f"{name} must be an array of real numbers"
            )
    elif kind not in "biuf":
        raise ArgumentTypeError(
            f"{name} must be an array of real numbers, got an array of dtype {raw.dtype}"
        )
    if ndim is not None and raw.ndim != ndim:
        raise ShapeError(f"{name} must be {ndim}-D, got shape {raw.shape}")
    try:
        return np.ascontiguousarray(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInputError(f"{name} must be an array of real numbers: {exc}") from None


def finite_array(x: Any, name: str, ndim: int) -> NDArray[np.float64]:
    """:func:`array`, also refusing NaN and infinity (naming the first bad entry)."""
    a = array(x, name, ndim)
    if not np.isfinite(a).all():
        k = int(np.flatnonzero(~np.isfinite(a.reshape(-1)))[0])
        raise NonFiniteError(
            f"{name} has a non-finite entry ({a.reshape(-1)[k]}) at flat index {k}"
        )
    return a


def contact_options(
    dim: Any,
    method: Any,
    tol: Any,
    max_iter: Any,
    relaxation: Any,
    facets: Any,
    eta: Any,
) -> tuple[int, float, int | None, float, int | None, float | None]:
    """The options of :func:`coulomb.contact.solve` (and of a simulation's contact solver),
    type- and range-checked: ``(dim, tol, max_iter, relaxation, facets, eta)``."""
    # the common call (defaults but dim and tol, plain Python numbers) costs a few
    # comparisons: the general checks below take about 1 us, a small solve's third
    if (
        type(dim) is int
        and (dim == 3 or dim == 2)
        and (method == "nsgs" or method == "prox" or method == "lemke")
        and type(tol) is float
        and 0.0 < tol < 1.0
        and max_iter is None
        and type(relaxation) is float
        and relaxation == 1.0
        and facets is None
        and eta is None
    ):
        return dim, tol, None, 1.0, None, None
    if isinstance(dim, (bool, np.bool_)) or not isinstance(dim, (int, np.integer)) or int(
        dim
    ) not in (2, 3):
        raise InvalidParameterError(f"dim must be 2 (planar) or 3 (spatial), got {dim!r}")
    choice("method", method, ("nsgs", "lemke", "prox"),
           "'nsgs' exact friction disk, 'lemke' polyhedral cone, 'prox' robust mode")
    t = tolerance("tol", tol)
    it = optional_count("max_iter", max_iter)
    om = real("relaxation", relaxation, low=0.0, high=2.0, low_open=True, high_open=True)
    if om != 1.0 and method != "nsgs":
        raise InvalidParameterError(f"relaxation does not apply to method={method!r} (nsgs only)")
    fa = optional_count("facets", facets, minimum=2, maximum=MAX_FACETS)
    if fa is not None and method != "lemke":
        raise InvalidParameterError(
            f"facets does not apply to method={method!r} (the polyhedral cone of 'lemke' only)"
        )
    et = None if eta is None else real("eta", eta, low=0.0, low_open=True)
    return int(dim), t, it, om, fa, et


def sticking(value: Any, method: str) -> bool:
    """The ``sticking`` option of a contact solve: a bool, and off only for ``"nsgs"`` (the
    other methods have no sweeps to end)."""
    on = boolean("sticking", value)
    if not on and method != "nsgs":
        raise InvalidParameterError(f"sticking does not apply to method={method!r} (nsgs only)")
    return on


def compressed_indices(
    name: str, indptr: Any, indices: Any, major: int, minor: int, where: str = ""
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Checks the index arrays of a compressed (CSR over ``major`` rows of ``minor`` columns,
    or CSC the other way round) matrix before anything trusts them (scipy's conversions do
    not, and read out of bounds on a bad index): ``indptr`` has ``major + 1`` entries, starts
    at 0, never decreases and ends within ``indices``; every index lies in ``[0, minor)``.
    Returns both as int64 (``indices`` cut to ``indptr[-1]``)."""
    p = np.asarray(indptr)
    i = np.asarray(indices)
    for arr, what in ((p, "index pointers"), (i, "indices")):
        if arr.ndim != 1 or not (arr.dtype.kind in "iu" or arr.size == 0):
            raise ShapeError(f"{where}{name}'s {what} must be a 1-D integer array")
    p = p.astype(np.int64, copy=False)
    i = i.astype(np.int64, copy=False)
    if p.shape[0] != major + 1:
        raise ShapeError(
            f"{where}{name} has {p.shape[0]} index pointers, expected {major + 1} "
            f"(one per {'row' if major else 'row/column'} plus one)"
        )
    if p[0] != 0 or (p.size > 1 and np.any(np.diff(p) < 0)):
        raise ShapeError(f"{where}{name}'s index pointers must start at 0 and never decrease")
    if p[-1] > i.shape[0]:
        raise ShapeError(
            f"{where}{name}'s index pointers end at {p[-1]}, beyond its {i.shape[0]} indices"
        )
    i = i[: p[-1]]
    if i.size and (i.min() < 0 or i.max() >= minor):
        bad = int(i[(i < 0) | (i >= minor)][0])
        raise ShapeError(f"{where}{name} has an index {bad} outside [0, {minor})")
    return p, i


def sparse_structure(name: str, W: Any) -> None:
    """Checks a scipy.sparse matrix's index arrays (they may have been changed after it was
    built) before scipy converts it, which would read out of bounds on a bad index."""
    shape = tuple(W.shape)
    fmt = getattr(W, "format", "")
    if fmt == "csr":
        compressed_indices(name, W.indptr, W.indices, shape[0], shape[1])
    elif fmt == "csc":
        compressed_indices(name, W.indptr, W.indices, shape[1], shape[0])
    elif fmt == "coo":
        coords = getattr(W, "coords", None) or (W.row, W.col)
        for ax, c in enumerate(coords):
            c = np.asarray(c)
            if c.size and (c.min() < 0 or c.max() >= shape[ax]):
                raise ShapeError(
                    f"{name} has a {'row' if ax == 0 else 'column'} index outside "
                    f"[0, {shape[ax]})"
                )
