"""The batch of :mod:`coulomb.contact`: :func:`solve_batch` and :class:`ContactBatchResult`
(exported by :mod:`coulomb.contact`)."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _validate
from ._batch import BatchResult, at_problem, count_of, per_problem, rows, stacked, threads_option
from .contact import ContactResult, Method, _friction
from .errors import InvalidParameterError, NonFiniteError, ShapeError
from .lcp import _as_array
from .settings import NSGSSettings, PolyhedralSettings, ProxSettings, accepts

__all__ = ["ContactBatchResult", "solve_batch"]


class ContactBatchResult(BatchResult[ContactResult]):
    """The answers of :func:`solve_batch`: one :class:`ContactResult` per problem (``r[i]``,
    iteration, slices), each equal entry by entry to what :func:`solve` returns for the
    problem alone, and the fields over the batch: ``success``, ``status``, ``message``,
    ``iterations``, ``error``, ``error_q``, ``error_q_floor``, ``scaled_error``,
    ``min_normal_impulse``,
    ``max_complementarity``, ``cone_violation``, ``dissipation_violation``, ``solve_time``
    (one entry per problem) and ``impulse``, ``velocity`` (shape ``(B, nc, dim)`` when every
    problem has nc contacts, else a list of ``(nc_i, dim)`` arrays).
    """

    _STATUS = ("solved", "iteration_limit", "numerical_failure")
    _VECTORS = ("impulse", "velocity")
    _SCALARS = ("iterations", "error", "error_q", "error_q_floor", "scaled_error",
                "min_normal_impulse",
                "max_complementarity", "cone_violation", "dissipation_violation", "solve_time")

    def __init__(self, columns: Mapping[str, Any], wall_time: float, dim: int,
                 shape: tuple[int, ...] | None = None) -> None:
        self._dim = dim
        super().__init__(columns, wall_time, shape)

    def _item_shape(self, i: int) -> tuple[int, ...]:
        n = int(self._offsets[i + 1] - self._offsets[i])
        return (n // self._dim, self._dim)

    def _item(self, i: int) -> ContactResult:
        c = self._cols
        out = {
            "impulse": self._vector("impulse", i),
            "velocity": self._vector("velocity", i),
            "success": bool(self.success[i]),
            "status": self._STATUS[int(c["status"][i])],
            "message": self._message(i),
            "iterations": int(c["iterations"][i]),
            "error": float(c["error"][i]),
            "error_q": float(c["error_q"][i]),
            "error_q_floor": float(c["error_q_floor"][i]),
            "scaled_error": float(c["scaled_error"][i]),
            "min_normal_impulse": float(c["min_normal_impulse"][i]),
            "max_complementarity": float(c["max_complementarity"][i]),
            "cone_violation": float(c["cone_violation"][i]),
            "dissipation_violation": float(c["dissipation_violation"][i]),
            "solve_time": float(c["solve_time"][i]),
        }
        return ContactResult(out, status=self.status[i])


def _batch_friction(
    mus: Any, qa: NDArray[np.float64] | list[NDArray[np.float64]], dim: int
) -> tuple[NDArray[np.float64] | list[NDArray[np.float64]], list[Any] | None]:
    """The friction coefficients of every problem (as the core takes them) and the
    anisotropic pairs (None when there are none): a scalar for all, a (B, nc) array, or one
    entry per problem as :func:`solve` takes ``mu``."""
    count = count_of(qa)
    if not isinstance(mus, (str, bytes, Sequence, np.ndarray)) or (
            isinstance(mus, np.ndarray) and mus.ndim == 0):
        mu0 = _friction(mus, 1, dim, dim)[0][0]  # a real number, finite and >= 0
        if isinstance(qa, np.ndarray):
            return np.full((count, qa.shape[1] // dim), mu0), None
        return [np.full(q.shape[0] // dim, mu0) for q in qa], None
    if isinstance(qa, np.ndarray):
        n = qa.shape[1]
        nc = n // dim
        if isinstance(mus, np.ndarray) and mus.shape == (count, nc):
            m2 = _as_array(mus, "mus", 2)
            bad = ~np.isfinite(m2)
            if bad.any():
                k, j = (int(v) for v in np.argwhere(bad)[0])
                raise NonFiniteError(f"problem {k}: mu contains NaN or infinity (mu[{j}])")
            if (m2 < 0).any():
                k, j = (int(v) for v in np.argwhere(m2 < 0)[0])
                raise InvalidParameterError(
                    f"problem {k}: friction coefficients must be >= 0, mu[{j}] = {m2[k, j]}")
            return m2, None
    entries = per_problem(mus, "mus", count)
    out, pairs = [], []
    for i, (mu, q) in enumerate(zip(entries, rows(qa), strict=True)):
        n = q.shape[0]
        mua, pp = at_problem(i, _friction, mu, n // dim, n, dim)
        out.append(mua)
        pairs.append(pp)
    return out, (pairs if any(p is not None for p in pairs) else None)


@accepts("method", (NSGSSettings, PolyhedralSettings, ProxSettings))
def solve_batch(
    Ws: ArrayLike | Sequence[ArrayLike],
    qs: ArrayLike | Sequence[ArrayLike],
    mus: ArrayLike | Sequence[ArrayLike],
    dim: int = 3,
    method: Method = "nsgs",
    *,
    tol: float = 1e-8,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    initial: Sequence[ArrayLike | None] | None = None,
    facets: int | None = None,
    eta: float | None = None,
    order: str = "forward",
    sticking: bool = True,
    settings: NSGSSettings | PolyhedralSettings | ProxSettings | None = None,
    threads: int | None = None,
) -> ContactBatchResult:
    """Solve many friction-contact problems ``u_i = W_i r_i + q_i`` at once, across the cores.

    Each problem is solved exactly as :func:`solve` solves it alone: the answers are bitwise
    those of one-at-a-time solves, whatever ``threads``. The GIL is released for the whole
    batch and Ctrl-C stops it (``KeyboardInterrupt``).

    Parameters
    ----------
    Ws : (B, n, n) array_like, or a sequence of (n_i, n_i) arrays
        The Delassus matrices, dense (``n = dim nc``): one stacked float64 array is read in
        place (no copy when C-contiguous); a sequence may mix sizes.
    qs : (B, n) array_like, or a sequence of (n_i,) arrays
        The free contact velocities.
    mus : float, (B, nc) array_like, or one entry per problem
        One friction coefficient for every contact of every problem, one row of coefficients
        per problem, or per problem anything :func:`solve` takes as ``mu`` (a scalar, ``(nc,)``
        or anisotropic ``(nc, 2)``).
    dim, method, tol, max_iter, relaxation, facets, eta, sticking, settings
        As for :func:`solve`, the same for every problem.
    initial : sequence, optional
        One warm start (``(nc, dim)`` or ``(dim nc,)``, or None) per problem (``"nsgs"`` and
        ``"prox"``).
    order : {"forward", "backward", "symmetric"}
        As for :func:`solve` (a permutation is not taken in a batch).
    threads : int, optional
        Threads to solve on, in [1, 1024] (default: all the cores). With one thread, or for a
        light batch (one problem, or a few hundred small ones), the calling thread solves it
        with the GIL released: waking a pool's threads would cost more than the solves.

    Returns
    -------
    ContactBatchResult
        One :class:`ContactResult` per problem, in order, and the fields over the batch.

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError
        Before any work, as :func:`solve` raises them; the message names the problem's index.
    """
    wall = time.perf_counter()
    dim, tol, max_iter, relaxation, facets, eta = _validate.contact_options(
        dim, method, tol, max_iter, relaxation, facets, eta)
    if method != "prox" and eta is not None:
        raise InvalidParameterError("eta applies to method='prox' only")
    sticks = _validate.sticking(sticking, method)
    if method == "lemke":
        if initial is not None:
            raise InvalidParameterError(
                "initial (warm start impulses) applies to method='nsgs' only")
        if facets is None:
            facets = 8 if dim == 3 else 2
        if dim == 2 and facets != 2:
            raise InvalidParameterError(
                f"facets must be 2 in 2D (the tangent directions +1 and -1, which are exact), "
                f"got {facets}")
        if dim == 3 and (facets < 4 or facets % 2 != 0):
            raise InvalidParameterError(
                f"facets must be even and at least 4 in 3D (tangent directions in +/- pairs), "
                f"got {facets}")
    if not isinstance(order, str) or order not in ("forward", "backward", "symmetric"):
        raise InvalidParameterError(
            f"order must be 'forward', 'backward' or 'symmetric' in a batch, got {order!r}")
    if order != "forward" and method != "nsgs":
        raise InvalidParameterError("order applies to method='nsgs' only")
    n_threads = threads_option(threads)
    Wa = stacked(Ws, "Ws", 2)
    qa = stacked(qs, "qs", 1)
    count = count_of(Wa)
    if count_of(qa) != count:
        raise ShapeError(f"Ws holds {count} problems but qs holds {count_of(qa)}")
    if not (isinstance(Wa, np.ndarray) and isinstance(qa, np.ndarray)):
        Wa, qa = rows(Wa), rows(qa)
    lengths = [qa.shape[1]] * min(count, 1) if isinstance(qa, np.ndarray) else [
        q.shape[0] for q in qa]
    for i, n in enumerate(lengths):
        if n % dim != 0:
            raise ShapeError(
                f"problem {i}: q has length {n}, which is not a multiple of dim = {dim}")
    mua, pairs = _batch_friction(mus, qa, dim)
    init: list[NDArray[np.float64] | None] | None = None
    if initial is not None:
        init = []
        entries = per_problem(initial, "initial", count)
        for i, (r0, q) in enumerate(zip(entries, rows(qa), strict=True)):
            if r0 is None:
                init.append(None)
                continue
            n = q.shape[0]
            a = _as_array(r0, f"initial[{i}]", None)
            if a.shape not in ((n // dim, dim), (n,)):
                got = "a scalar" if np.ndim(r0) == 0 else f"shape {a.shape}"
                raise ShapeError(f"problem {i}: initial must have shape ({n // dim}, {dim}) or "
                                 f"({n},), got {got}")
            a = np.ascontiguousarray(a.reshape(n))
            if not np.isfinite(a).all():
                raise NonFiniteError(f"problem {i}: initial contains NaN or infinity")
            init.append(a)
    out = _core.contact_solve_batch(
        Wa, qa, mua, dim, method, float(tol), None if max_iter is None else int(max_iter),
        float(relaxation), init, facets, pairs, None if eta is None else float(eta), order,
        n_threads, sticks)
    shape = (qa.shape[1] // dim, dim) if isinstance(qa, np.ndarray) else None
    return ContactBatchResult(out, time.perf_counter() - wall, dim, shape)
