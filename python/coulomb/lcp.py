"""Linear complementarity problems: find z with ``0 <= z ⊥ w = M z + q >= 0``.

>>> import numpy as np, coulomb
>>> r = coulomb.lcp.solve([[2.0]], [-6.0])      # the seed's w = 2z - 6
>>> float(r.z[0]), float(r.w[0]), r.status
(3.0, 0.0, 'solved')
>>> coulomb.lcp.solve([[-1.0]], [-1.0]).status  # w = -z - 1 has no solution
'ray_termination'

Methods:

``"lemke"`` (default)
    Lemke's complementary pivoting with a lexicographic ratio test (z0 leaves first on ties),
    tolerances relative to the data's scale and a final polish of the terminal basis. Finite on
    degenerate problems; a *secondary ray* is reported as ``status="ray_termination"``, which for
    copositive-plus M (e.g. positive semidefinite) proves that no solution exists.
``"pgs"``
    Projected Gauss-Seidel / SOR for symmetric M with a positive diagonal.
``"enumerate"``
    Every complementary basis (n <= 15): returns *all* solutions in ``solutions``; the oracle
    for tests.

Every answer is judged on the original data: ``w`` is recomputed as ``M z + q`` and ``error``
is ``||min(z, w)||_2 / max(1, ||q||_2)`` (the measure Siconos and the literature report).
``success`` is True only if ``error <= tol`` and ``scaled_error <= tol`` (the same test on the
equilibrated problem, so a tiny ``q`` cannot hide a wrong answer).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._result import Result
from .errors import InvalidInputError, InvalidParameterError, ShapeError

__all__ = ["LcpResult", "check", "solve"]

Method = Literal["lemke", "pgs", "enumerate"]
_METHODS = ("lemke", "pgs", "enumerate")
Engine = Literal["auto", "tableau", "product_form"]
_ENGINES = ("auto", "tableau", "product_form")
_F64 = np.dtype(np.float64)


class LcpResult(Result):
    """The answer of :func:`solve`.

    Attributes
    ----------
    z, w : ndarray
        The solution and ``w = M z + q`` recomputed from the original data.
    success : bool
        True only if the answer passes ``tol`` on the original data.
    status : str
        ``"solved"``, ``"ray_termination"``, ``"pivot_limit"``, ``"iteration_limit"``,
        ``"numerical_failure"`` or ``"no_solution"`` (enumeration).
    message : str
        One line for a person.
    error : float
        ``||min(z, w)||_2 / max(1, ||q||_2)``.
    scaled_error : float
        ``||min(z', w')||_inf`` on the equilibrated problem (unit-free).
    min_z, min_w, max_complementarity : float
        ``min z``, ``min w`` and ``max |z_i w_i|``.
    pivots, iterations : int
        Basis exchanges (Lemke); sweeps (PGS) or bases examined (enumeration).
    basis : ndarray of int
        Indices i with z_i basic at the end: pass it as the next ``warm_start``.
    warm_start : str
        ``"none"``, ``"accepted"`` (the guess solved it, no pivots) or ``"rejected"`` (cold
        start).
    pivots_saved : int
        Lower bound on the pivots an accepted warm start saved (``len(basis) + 1``).
    polished : bool
        Whether re-solving the final basis's principal system improved the answer.
    restarts : int
        Extra covering vectors Lemke tried after a ray termination.
    solutions : ndarray, shape (k, n)
        Every distinct solution (enumeration only).
    solve_time : float
        Seconds spent in the Rust core.
    """

    z: NDArray[np.float64]
    w: NDArray[np.float64]
    success: bool
    status: str
    message: str
    error: float
    scaled_error: float
    min_z: float
    min_w: float
    max_complementarity: float
    pivots: int
    iterations: int
    basis: NDArray[np.int64]
    warm_start: str
    pivots_saved: int
    polished: bool
    restarts: int
    solutions: NDArray[np.float64]
    solve_time: float


def _as_array(x: ArrayLike, name: str, ndim: int) -> NDArray[np.float64]:
    """float64, C-contiguous, of the given dimension; no copy when it already is."""
    if (
        type(x) is np.ndarray
        and x.dtype == np.float64
        and x.ndim == ndim
        and x.flags.c_contiguous
    ):
        return x
    if hasattr(x, "toarray") and callable(x.toarray):  # scipy.sparse
        x = x.toarray()
    if np.iscomplexobj(x):
        raise InvalidInputError(f"{name} must be real, got a complex array")
    try:
        arr = np.ascontiguousarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be an array of real numbers: {exc}") from None
    if arr.ndim != ndim:
        raise ShapeError(f"{name} must be {ndim}-D, got shape {arr.shape}")
    return arr


def _basis_indices(warm_start: Any, n: int) -> list[int] | None:
    if warm_start is None:
        return None
    if isinstance(warm_start, LcpResult):
        warm_start = warm_start.basis
    arr = np.asarray(warm_start)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise ShapeError(f"a boolean warm_start must have shape ({n},), got {arr.shape}")
        return [int(i) for i in np.flatnonzero(arr)]
    if arr.size == 0:
        return []
    if arr.ndim != 1 or not np.issubdtype(arr.dtype, np.integer):
        raise InvalidParameterError(
            "warm_start must be indices (ints), a boolean mask, or a previous LcpResult"
        )
    if (arr < 0).any() or (arr >= n).any():
        raise InvalidParameterError(f"warm_start indices must lie in [0, {n}), got {arr.tolist()}")
    return [int(i) for i in arr]


def solve(
    M: ArrayLike,
    q: ArrayLike,
    method: Method = "lemke",
    *,
    tol: float = 1e-9,
    max_pivots: int | None = None,
    covering_vector: ArrayLike | None = None,
    warm_start: Sequence[int] | NDArray[Any] | LcpResult | None = None,
    polish: bool = True,
    restarts: int = 2,
    max_iter: int = 10_000,
    relaxation: float = 1.0,
    initial: ArrayLike | None = None,
    engine: Engine = "auto",
) -> LcpResult:
    """Solve the LCP ``0 <= z ⊥ M z + q >= 0``.

    Parameters
    ----------
    M : (n, n) array_like
        The matrix (dense; scipy.sparse is densified). Ints and lists are converted.
    q : (n,) array_like
        The vector.
    method : {"lemke", "pgs", "enumerate"}
        See the module documentation.
    tol : float
        Tolerance on ``error`` and ``scaled_error`` for ``success``.
    max_pivots : int, optional
        Lemke's pivot limit (default ``max(1000, 50 n)``).
    covering_vector : (n,) array_like, optional
        Lemke's covering vector d > 0, in the units of q. Default: all ones on the equilibrated
        problem, which makes the pivot path independent of the rows' units. Pass
        ``np.ones(n)`` for textbook Lemke.
    warm_start : indices, boolean mask or LcpResult, optional
        A guessed basis (the indices with z_i > 0, e.g. the previous time step's
        ``result.basis``). If it solves the problem no pivot is made; else Lemke starts cold.
    polish : bool
        Re-solve the final basis's principal system on the original data; keep it if better.
    restarts : int
        After a ray termination, how many other covering vectors Lemke tries (only when
        ``covering_vector`` is not given).
    max_iter : int
        PGS sweep limit.
    relaxation : float
        PGS over-relaxation ω in (0, 2).
    initial : (n,) array_like, optional
        PGS starting point.
    engine : {"auto", "tableau", "product_form"}
        How Lemke keeps the basis inverse. ``"product_form"`` (a file of eta vectors) costs
        O(n k) for the k-th pivot, ``"tableau"`` O(n^2). ``"auto"`` takes the product form for
        16 <= n <= 1024 and re-runs the path on the tableau if it does not end in a solution
        within 2n + 16 pivots (the message then says so).

    Returns
    -------
    LcpResult

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError, ProblemTooLargeError
        Before any work, for bad input.
    """
    # The common call (float64 C-contiguous arrays, default options) skips the generic
    # conversions: for small n the Python layer would otherwise cost more than the solve.
    if (
        type(M) is np.ndarray
        and type(q) is np.ndarray
        and M.dtype == _F64
        and q.dtype == _F64
        and M.flags.c_contiguous
        and q.flags.c_contiguous
        and M.ndim == 2
        and q.ndim == 1
    ):
        Ma, qa = M, q
    else:
        Ma = _as_array(M, "M", 2)
        qa = _as_array(q, "q", 1)
    n = qa.shape[0]
    if Ma.shape != (n, n):
        raise ShapeError(f"M must have shape ({n}, {n}) to match q of length {n}, got {Ma.shape}")
    if method not in _METHODS:
        raise InvalidParameterError(f"unknown method {method!r}: expected one of {_METHODS}")
    if engine not in _ENGINES:
        raise InvalidParameterError(f"unknown engine {engine!r}: expected one of {_ENGINES}")
    cover = None if covering_vector is None else _as_array(covering_vector, "covering_vector", 1)
    init = None if initial is None else _as_array(initial, "initial", 1)
    if max_pivots is not None and max_pivots < 1:
        raise InvalidParameterError(f"max_pivots must be at least 1, got {max_pivots}")
    if restarts < 0 or max_iter < 1:
        raise InvalidParameterError("restarts must be >= 0 and max_iter >= 1")
    out = _core.lcp_solve(
        Ma,
        qa,
        method,
        float(tol),
        max_pivots,
        cover,
        None if warm_start is None else _basis_indices(warm_start, n),
        bool(polish),
        int(restarts),
        int(max_iter),
        float(relaxation),
        init,
        engine,
    )
    return LcpResult(out)


def check(M: ArrayLike, q: ArrayLike, z: ArrayLike) -> Result:
    """The error measures of any answer z (yours or another solver's) on the original data.

    Returns a result with ``w``, ``error``, ``scaled_error``, ``min_z``, ``min_w`` and
    ``max_complementarity``, computed exactly as :func:`solve` computes its own.
    """
    Ma = _as_array(M, "M", 2)
    qa = _as_array(q, "q", 1)
    za = _as_array(z, "z", 1)
    n = qa.shape[0]
    if Ma.shape != (n, n):
        raise ShapeError(f"M must have shape ({n}, {n}) to match q of length {n}, got {Ma.shape}")
    return Result(_core.lcp_measures(Ma, qa, za))
