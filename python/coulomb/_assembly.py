r"""From a mechanism to its contact problem (re-exported by :mod:`coulomb.contact`).

.. code-block:: text

    W = G^T M^-1 G,        q = G^T v_free + extra,        v = v_free + M^-1 G r

M is the symmetric positive definite mass matrix (``ndof x ndof``), G the transposed contact
Jacobian (``ndof x dim nc``: column k is the generalized direction of contact component k,
normal first per contact, then its tangents), ``v_free`` the velocity reached without
contact impulses and r the impulses. M is factored in Rust by Cholesky: block by block when it
is block diagonal with blocks of at most 256 dofs (rigid bodies, diagonal masses; the blocks
are found from the sparsity pattern), otherwise by faer's sparse Cholesky.

>>> import numpy as np, coulomb
>>> # the chapter's inelastic step: a particle of mass 2, free velocity (-3, 1) in the contact
>>> # frame
>>> W, q = coulomb.contact.assemble(2 * np.eye(2), np.eye(2), [-3.0, 1.0])
>>> W.round(12).tolist(), q.tolist()
([[0.5, 0.0], [0.0, 0.5]], [-3.0, 1.0])
>>> r = coulomb.contact.solve(W, q, 0.2, dim=2)
>>> coulomb.contact.post_velocity(2 * np.eye(2), np.eye(2), [-3.0, 1.0], r.impulse).round(12)
array([0. , 0.4])
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from .errors import InvalidInputError, InvalidParameterError, NonFiniteError, ShapeError
from .lcp import _as_array

__all__ = ["assemble", "post_velocity"]

Triplets = tuple[int, int, NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]


def _triplets(a: Any, name: str, diagonal_ok: bool = False) -> Triplets:
    """(nrows, ncols, rows, cols, values) of a dense array, a scipy.sparse matrix, or (for M)
    a 1-D array of diagonal entries."""
    if hasattr(a, "tocoo") and callable(a.tocoo):  # scipy.sparse
        coo = a.tocoo()
        if np.iscomplexobj(coo.data):
            raise InvalidInputError(f"{name} must be real, got a complex matrix")
        vals = np.ascontiguousarray(coo.data, dtype=np.float64)
        if not np.isfinite(vals).all():
            raise NonFiniteError(f"{name} contains NaN or infinity")
        r, c = coo.shape
        return (
            int(r),
            int(c),
            np.ascontiguousarray(coo.row, dtype=np.int64),
            np.ascontiguousarray(coo.col, dtype=np.int64),
            vals,
        )
    arr = _as_array(a, name, None)
    if arr.ndim == 1 and diagonal_ok:
        n = arr.shape[0]
        idx = np.arange(n, dtype=np.int64)
        return n, n, idx, idx.copy(), arr
    if arr.ndim != 2:
        raise ShapeError(f"{name} must be 2-D, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise NonFiniteError(f"{name} contains NaN or infinity")
    rows, cols = np.nonzero(arr)
    return (
        int(arr.shape[0]),
        int(arr.shape[1]),
        rows.astype(np.int64),
        cols.astype(np.int64),
        np.ascontiguousarray(arr[rows, cols]),
    )


def _check_mg(m: Triplets, g: Triplets) -> None:
    if m[0] != m[1]:
        raise ShapeError(f"M must be square, got {m[0]} x {m[1]}")
    if g[0] != m[0]:
        raise ShapeError(
            f"G must have ndof = {m[0]} rows (one per generalized velocity, like M), got {g[0]}"
        )


def _vector(x: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    arr = _as_array(x, name, 1)
    if arr.shape[0] != n:
        raise ShapeError(f"{name} must have {n} entries, got {arr.shape[0]}")
    if not np.isfinite(arr).all():
        raise NonFiniteError(f"{name} contains NaN or infinity")
    return arr


def assemble(
    M: ArrayLike,
    G: ArrayLike,
    v_free: ArrayLike | None = None,
    *,
    force: ArrayLike | None = None,
    extra: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The contact problem ``(W, q)`` of a mechanism: ``W = G^T M^-1 G``,
    ``q = G^T v_free + extra``.

    Parameters
    ----------
    M : (ndof, ndof) array_like or scipy.sparse matrix, or (ndof,) array_like
        The mass matrix, symmetric positive definite; a 1-D array is a diagonal.
    G : (ndof, dim nc) array_like or scipy.sparse matrix
        The contact directions in generalized coordinates, one column per contact component
        (normal first per contact).
    v_free : (ndof,) array_like, optional
        The free velocity. Give it or ``force``.
    force : (ndof,) array_like, optional
        Instead of ``v_free``: a force impulse f with ``v_free = M^-1 f`` (FCLib's global form
        ``M v = H r + f``).
    extra : (dim nc,) array_like, optional
        A term added to q (a restitution term, FCLib's ``w``).

    Returns
    -------
    W : ndarray, shape (dim nc, dim nc)
        Dense for now, exactly symmetric.
    q : ndarray, shape (dim nc,)

    Raises
    ------
    ShapeError, NonFiniteError
        For shapes that do not fit and NaN or infinity.
    InvalidParameterError
        When M is not symmetric or not positive definite (the message names M), or when both
        or neither of ``v_free`` and ``force`` are given.
    """
    m = _triplets(M, "M", diagonal_ok=True)
    g = _triplets(G, "G")
    _check_mg(m, g)
    if (v_free is None) == (force is None):
        raise InvalidParameterError(
            "give exactly one of v_free (free velocity) and force (f, with v_free = M^-1 f)"
        )
    v = None if v_free is None else _vector(v_free, "v_free", m[0])
    f = None if force is None else _vector(force, "force", m[0])
    e = None if extra is None else _vector(extra, "extra", g[1])
    W, q, _ = _core.contact_assemble(m, g, v, f, e)
    return W, q


def post_velocity(
    M: ArrayLike, G: ArrayLike, v_free: ArrayLike, impulse: ArrayLike
) -> NDArray[np.float64]:
    """The velocity after the contact impulses, ``v = v_free + M^-1 G r``.

    ``impulse`` is r, of shape ``(nc, dim)`` (a :class:`coulomb.ContactResult`'s ``impulse``) or
    ``(dim nc,)``; M and G as for :func:`assemble`.
    """
    m = _triplets(M, "M", diagonal_ok=True)
    g = _triplets(G, "G")
    _check_mg(m, g)
    v = _vector(v_free, "v_free", m[0])
    r = _as_array(impulse, "impulse", np.ndim(impulse)).reshape(-1)
    r = _vector(np.ascontiguousarray(r), "impulse", g[1])
    return _core.contact_post_velocity(m, g, v, r)
