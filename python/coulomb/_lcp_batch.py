"""The batch of :mod:`coulomb.lcp`: :func:`solve_batch` and :class:`LcpBatchResult` (exported
by :mod:`coulomb.lcp`)."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _validate
from ._batch import BatchResult, at_problem, count_of, per_problem, rows, stacked, threads_option
from .errors import ShapeError
from .lcp import (
    _ENGINES,
    _MAX_RESTARTS,
    _METHODS,
    Engine,
    LcpResult,
    Method,
    _as_array,
    _basis_indices,
)
from .settings import LemkeSettings, PGSSettings, accepts

__all__ = ["LcpBatchResult", "solve_batch"]


class LcpBatchResult(BatchResult[LcpResult]):
    """The answers of :func:`solve_batch`: one :class:`LcpResult` per problem (``r[i]``,
    iteration, slices), each equal entry by entry to what :func:`solve` returns for the
    problem alone, and the fields over the batch: ``success``, ``status``, ``message``,
    ``error``, ``scaled_error``, ``min_z``, ``min_w``, ``max_complementarity``, ``pivots``,
    ``iterations``, ``pivots_saved``, ``restarts``, ``polished``, ``solve_time`` (one entry per
    problem) and ``z``, ``w`` (shape ``(B, n)`` when every problem has size n, else a list).
    """

    _STATUS = ("solved", "ray_termination", "pivot_limit", "iteration_limit",
               "numerical_failure", "no_solution")
    _VECTORS = ("z", "w")
    _SCALARS = ("error", "scaled_error", "min_z", "min_w", "max_complementarity", "pivots",
                "iterations", "pivots_saved", "restarts", "polished", "solve_time")
    _WARM = ("none", "accepted", "rejected")

    def _item(self, i: int) -> LcpResult:
        c = self._cols
        n = int(self._offsets[i + 1] - self._offsets[i])
        sa, sb = self._solution_span(i)
        sols = np.array(c["solutions"][sa:sb])
        out = {
            "success": bool(self.success[i]),
            "status": self._STATUS[int(c["status"][i])],
            "message": self._message(i),
            "z": self._vector("z", i),
            "w": self._vector("w", i),
            "error": float(c["error"][i]),
            "scaled_error": float(c["scaled_error"][i]),
            "min_z": float(c["min_z"][i]),
            "min_w": float(c["min_w"][i]),
            "max_complementarity": float(c["max_complementarity"][i]),
            "pivots": int(c["pivots"][i]),
            "iterations": int(c["iterations"][i]),
            "basis": self._basis(i),
            "warm_start": self._WARM[int(c["warm_start"][i])],
            "pivots_saved": int(c["pivots_saved"][i]),
            "polished": bool(c["polished"][i]),
            "restarts": int(c["restarts"][i]),
            "solutions": sols.reshape((sols.size // n if n else 0, n)),
            "solve_time": float(c["solve_time"][i]),
        }
        return LcpResult(out, status=self.status[i])

    @property
    def basis(self) -> list[NDArray[np.int64]]:
        """Per problem, the indices with z_i basic at the end (pass the whole result as the
        next batch's ``warm_start``)."""
        return [self._basis(i) for i in range(len(self))]

    def _basis(self, i: int) -> NDArray[np.int64]:
        # in the layout of z: problem i's indices start where its z does
        a = int(self._offsets[i])
        return np.array(self._cols["basis"][a:a + int(self._cols["basis_count"][i])])

    def _solution_span(self, i: int) -> tuple[int, int]:
        """Where problem i's solutions are in the flat ``solutions`` (only enumeration has
        any; the offsets are summed once, when first needed)."""
        ends = self.__dict__.get("_solution_ends")
        if ends is None:
            c = self._cols
            sizes = np.diff(self._offsets) * np.asarray(c["solution_count"])
            ends = np.concatenate(([0], np.cumsum(sizes)))
            self._solution_ends = ends
        return int(ends[i]), int(ends[i + 1])


def _per_problem_vectors(value: Any, name: str, sizes: list[int]
                         ) -> list[NDArray[np.float64] | None] | None:
    """An (n,) vector for every problem (all of size n), or one entry per problem (None for
    the default), each checked and named ``name[i]``."""
    if value is None:
        return None
    if (isinstance(value, np.ndarray) and value.ndim == 1) or (
            isinstance(value, Sequence) and value and np.isscalar(value[0])):
        one = _as_array(value, name, 1)
        return [one] * len(sizes)
    entries = per_problem(value, name, len(sizes))
    return [None if v is None else _as_array(v, f"{name}[{i}]", 1)
            for i, v in enumerate(entries)]


@accepts("method", (LemkeSettings, PGSSettings))
def solve_batch(
    Ms: ArrayLike | Sequence[ArrayLike],
    qs: ArrayLike | Sequence[ArrayLike],
    method: Method = "lemke",
    *,
    tol: float = 1e-9,
    max_pivots: int | None = None,
    covering_vector: ArrayLike | Sequence[ArrayLike | None] | None = None,
    warm_start: Sequence[Any] | LcpBatchResult | None = None,
    polish: bool | None = None,
    restarts: int | None = None,
    max_iter: int | None = None,
    relaxation: float | None = None,
    initial: ArrayLike | Sequence[ArrayLike | None] | None = None,
    engine: Engine | None = None,
    settings: LemkeSettings | PGSSettings | None = None,
    threads: int | None = None,
) -> LcpBatchResult:
    """Solve many LCPs ``0 <= z_i ⊥ M_i z_i + q_i >= 0`` at once, across the cores.

    Each problem is solved exactly as :func:`solve` solves it alone (the same code, its own
    workspace): the answers are bitwise those of one-at-a-time solves, whatever ``threads``.
    The GIL is released for the whole batch and Ctrl-C stops it (``KeyboardInterrupt``).

    Parameters
    ----------
    Ms : (B, n, n) array_like, or a sequence of (n_i, n_i) arrays
        The matrices: one stacked float64 array is read in place (no copy when C-contiguous);
        a sequence may mix sizes.
    qs : (B, n) array_like, or a sequence of (n_i,) arrays
        The vectors, one per matrix.
    method, tol, max_pivots, polish, restarts, max_iter, relaxation, engine, settings
        As for :func:`solve`, the same for every problem.
    covering_vector, initial : (n,) array_like, or one entry per problem, optional
        As for :func:`solve`: one vector for every problem (all of size n), or a sequence with
        one vector (or None) per problem.
    warm_start : sequence of bases, or LcpBatchResult, optional
        One guessed basis (or None) per problem, as :func:`solve` takes it; a previous
        batch's result gives each problem its basis.
    threads : int, optional
        Threads to solve on, in [1, 1024] (default: all the cores). With one thread, or for a
        light batch (one problem, or a few hundred small ones), the calling thread solves it
        with the GIL released: waking a pool's threads would cost more than the solves.

    Returns
    -------
    LcpBatchResult
        One :class:`LcpResult` per problem, in order, and the fields over the batch.

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError, ProblemTooLargeError
        Before any work, as :func:`solve` raises them; the message names the argument and
        the problem's index.
    """
    wall = time.perf_counter()
    Ma = stacked(Ms, "Ms", 2)
    qa = stacked(qs, "qs", 1)
    count = count_of(Ma)
    if count_of(qa) != count:
        raise ShapeError(f"Ms holds {count} problems but qs holds {count_of(qa)}")
    if isinstance(Ma, np.ndarray) and isinstance(qa, np.ndarray):
        if Ma.shape[1] != Ma.shape[2] or qa.shape[1:] != Ma.shape[1:2]:
            raise ShapeError(
                f"Ms must have shape (B, n, n) and qs (B, n), got {Ma.shape} and {qa.shape}")
        sizes = [Ma.shape[1]] * count
    else:
        Ma, qa = rows(Ma), rows(qa)
        sizes = [m.shape[0] for m in Ma]
    n_threads = threads_option(threads)
    if type(tol) is not float or not 0.0 < tol < 1.0:
        tol = _validate.tolerance("tol", tol)
    cover = init = basis = None
    if method == "lemke":
        _validate.unused("method", method, max_iter=max_iter, relaxation=relaxation,
                         initial=initial)
        max_piv = None if max_pivots is None else _validate.count("max_pivots", max_pivots)
        n_restarts = 2 if restarts is None else _validate.count(
            "restarts", restarts, minimum=0, maximum=_MAX_RESTARTS)
        do_polish = True if polish is None else _validate.boolean("polish", polish)
        eng = "auto" if engine is None else _validate.choice("engine", engine, _ENGINES)
        cover = _per_problem_vectors(covering_vector, "covering_vector", sizes)
        if warm_start is not None:
            guesses = per_problem(warm_start.basis if isinstance(warm_start, LcpBatchResult)
                                  else warm_start, "warm_start", count)
            basis = [at_problem(i, _basis_indices, g, sizes[i]) for i, g in enumerate(guesses)]
        sweeps, omega = 10_000, 1.0
    else:
        _validate.choice("method", method, _METHODS)
        _validate.unused("method", method, max_pivots=max_pivots,
                         covering_vector=covering_vector, warm_start=warm_start,
                         polish=polish, restarts=restarts, engine=engine)
        if method == "enumerate":
            _validate.unused("method", method, max_iter=max_iter, relaxation=relaxation,
                             initial=initial)
        sweeps = 10_000 if max_iter is None else _validate.count("max_iter", max_iter)
        omega = 1.0 if relaxation is None else _validate.real(
            "relaxation", relaxation, low=0.0, high=2.0, low_open=True, high_open=True)
        init = _per_problem_vectors(initial, "initial", sizes)
        if init is not None:
            for i, v in enumerate(init):
                if v is not None:
                    at_problem(i, _validate.finite_array, v, f"initial[{i}]", 1)
        max_piv, n_restarts, do_polish, eng = None, 2, True, "auto"
    out = _core.lcp_solve_batch(Ma, qa, method, tol, max_piv, cover, basis, do_polish,
                                n_restarts, sweeps, omega, init, eng, n_threads)
    shape = (Ma.shape[1],) if isinstance(Ma, np.ndarray) else None
    return LcpBatchResult(out, time.perf_counter() - wall, shape)
