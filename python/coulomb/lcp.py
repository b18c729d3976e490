"""Linear complementarity problems: find z with ``0 <= z ⊥ w = M z + q >= 0``.

>>> import numpy as np, coulomb
>>> r = coulomb.lcp.solve([[2.0]], [-6.0])      # the chapter's w = 2z - 6
>>> float(r.z[0]), float(r.w[0]), r.status
(3.0, 0.0, Status.SOLVED)
>>> coulomb.lcp.solve([[-1.0]], [-1.0]).status  # w = -z - 1 has no solution
Status.RAY_TERMINATION

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

from . import _core, _validate
from ._result import Result
from ._status import Status
from .errors import ArgumentTypeError, InvalidParameterError, ShapeError
from .settings import LemkeSettings, PGSSettings, accepts

__all__ = ["LcpBatchResult", "LcpResult", "check", "solve", "solve_batch"]

Method = Literal["lemke", "pgs", "enumerate"]
_METHODS = ("lemke", "pgs", "enumerate")
Engine = Literal["auto", "tableau", "product_form"]
_ENGINES = ("auto", "tableau", "product_form")
_F64 = np.dtype(np.float64)
#: the most covering vectors Lemke tries after the first (Rust ``lcp::lemke::MAX_RESTARTS``).
_MAX_RESTARTS = 1000


class LcpResult(Result):
    """The answer of :func:`solve`.

    Attributes
    ----------
    z, w : ndarray
        The solution and ``w = M z + q`` recomputed from the original data.
    success : bool
        True only if the answer passes ``tol`` on the original data.
    status : Status
        ``Status.SOLVED``, ``RAY_TERMINATION``, ``PIVOT_LIMIT``, ``ITERATION_LIMIT``,
        ``NUMERICAL_FAILURE`` or ``NO_SOLUTION`` (enumeration); each equals its string
        (``r.status == "solved"``).
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
        Extra covering vectors Lemke tried after a ray termination or a terminal basis
        whose answer failed ``tol``.
    solutions : ndarray, shape (k, n)
        Every distinct solution (enumeration only).
    solve_time : float
        Seconds spent in the Rust core.
    """

    z: NDArray[np.float64]
    w: NDArray[np.float64]
    success: bool
    status: Status
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


def _as_array(x: ArrayLike, name: str, ndim: int | None) -> NDArray[np.float64]:
    """float64, C-contiguous, of the given dimension; no copy when it already is (see
    :func:`coulomb._validate.array` for what is refused)."""
    return _validate.array(x, name, ndim)


def _basis_indices(warm_start: Any, n: int) -> list[int] | None:
    if warm_start is None:
        return None
    if isinstance(warm_start, LcpResult):
        warm_start = warm_start.basis
    if isinstance(warm_start, (str, bytes)) or np.ndim(warm_start) > 1:
        raise ArgumentTypeError(
            "warm_start must be indices (ints), a boolean mask, or a previous LcpResult, "
            f"got {warm_start!r}"
        )
    try:
        arr = np.asarray(warm_start)
    except ValueError:
        raise InvalidParameterError("warm_start must be a flat sequence of indices") from None
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


@accepts("method", (LemkeSettings, PGSSettings))
def solve(
    M: ArrayLike,
    q: ArrayLike,
    method: Method = "lemke",
    *,
    tol: float = 1e-9,
    max_pivots: int | None = None,
    covering_vector: ArrayLike | None = None,
    warm_start: Sequence[int] | NDArray[Any] | LcpResult | None = None,
    polish: bool | None = None,
    restarts: int | None = None,
    max_iter: int | None = None,
    relaxation: float | None = None,
    initial: ArrayLike | None = None,
    engine: Engine | None = None,
    settings: LemkeSettings | PGSSettings | None = None,
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
        Tolerance on ``error`` and ``scaled_error`` for ``success``, in (0, 1).
    max_pivots : int, optional
        Lemke's pivot limit, an int in [1, 10^9] (default ``max(1000, 50 n)``).
    covering_vector : (n,) array_like, optional
        Lemke's covering vector d > 0, in the units of q. Default: all ones on the equilibrated
        problem, which makes the pivot path independent of the rows' units. Pass
        ``np.ones(n)`` for textbook Lemke.
    warm_start : indices, boolean mask or LcpResult, optional
        A guessed basis (the indices with z_i > 0, e.g. the previous time step's
        ``result.basis``). If it solves the problem no pivot is made; else Lemke starts cold.
    polish : bool
        Re-solve the final basis's principal system on the original data; keep it if better
        (default True).
    restarts : int
        After a ray termination, or a terminal basis whose answer fails ``tol`` (rounding
        on a degenerate path), how many other covering vectors Lemke tries (only when
        ``covering_vector`` is not given): an int in [0, 1000], default 2.
    max_iter : int
        PGS sweep limit, an int in [1, 10^9] (default 10,000).
    relaxation : float
        PGS over-relaxation ω in (0, 2) (default 1).
    initial : (n,) array_like, optional
        PGS starting point.
    engine : {"auto", "tableau", "product_form"}
        How Lemke keeps the basis inverse. ``"product_form"`` (a file of eta vectors) costs
        O(n k) for the k-th pivot, ``"tableau"`` O(n^2). ``"auto"`` takes the product form for
        16 <= n <= 1024 and re-runs the path on the tableau if it does not end in a solution
        within 2n + 16 pivots (the message then says so).
    settings : LemkeSettings or PGSSettings, optional
        The method and its options as one object (:mod:`coulomb.settings`), in place of
        ``method`` and the keywords above; ``warm_start`` and ``initial`` combine with it. A
        keyword also given in it raises :class:`~coulomb.errors.SettingsConflictError`.

    Returns
    -------
    LcpResult

    The options of one method (``max_pivots``, ``covering_vector``, ``warm_start``,
    ``polish``, ``restarts``, ``engine`` for Lemke; ``max_iter``, ``relaxation``, ``initial``
    for PGS) are refused with another method. Ctrl-C stops the solve (``KeyboardInterrupt``).

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError, ProblemTooLargeError
        Before any work, for bad input (:class:`~coulomb.errors.ArgumentTypeError`, also a
        ``TypeError``, for an argument of the wrong type).
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
    # M square and q of its size: checked by the core before any work (ShapeError)
    n = Ma.shape[0]
    if type(tol) is not float or not 0.0 < tol < 1.0:
        tol = _validate.tolerance("tol", tol)
    if method == "lemke":
        if max_iter is not None or relaxation is not None or initial is not None:
            _validate.unused("method", method, max_iter=max_iter, relaxation=relaxation,
                             initial=initial)
        max_piv = None if max_pivots is None else _validate.count("max_pivots", max_pivots)
        n_restarts = 2 if restarts is None else _validate.count(
            "restarts", restarts, minimum=0, maximum=_MAX_RESTARTS)
        do_polish = True if polish is None else _validate.boolean("polish", polish)
        eng = "auto" if engine is None else _validate.choice("engine", engine, _ENGINES)
        cover = (None if covering_vector is None
                 else _as_array(covering_vector, "covering_vector", 1))
        basis = None if warm_start is None else _basis_indices(warm_start, n)
        # the core fills an LcpResult itself (its status a Status member)
        return _core.lcp_solve(Ma, qa, method, tol, max_piv, cover, basis, do_polish,
                               n_restarts, 10_000, 1.0, None, eng)
    _validate.choice("method", method, _METHODS)
    _validate.unused("method", method, max_pivots=max_pivots, covering_vector=covering_vector,
                     warm_start=warm_start, polish=polish, restarts=restarts, engine=engine)
    if method == "enumerate":
        _validate.unused("method", method, max_iter=max_iter, relaxation=relaxation,
                         initial=initial)
    sweeps = 10_000 if max_iter is None else _validate.count("max_iter", max_iter)
    omega = 1.0 if relaxation is None else _validate.real(
        "relaxation", relaxation, low=0.0, high=2.0, low_open=True, high_open=True)
    init = None if initial is None else _validate.finite_array(initial, "initial", 1)
    return _core.lcp_solve(Ma, qa, method, tol, None, None, None, True, 2, sweeps, omega,
                           init, "auto")


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


# the batch (its own file); imported last, as it reads the names above
from ._lcp_batch import LcpBatchResult, solve_batch  # noqa: E402
