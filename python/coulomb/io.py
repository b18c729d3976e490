"""Readers for the standard benchmark problem formats.

The Siconos text format is read by the Rust core (``coulomb._core``); see
``../shared/data/siconos-lcp/SOURCE.md`` and ``../shared/data/siconos-fc/SOURCE.md`` for the
layout (dense column-major, sparse-block and CSparse storage). FCLib's HDF5 files are read by
:func:`read_fclib` with h5py (the optional extra ``coulomb[hdf5]``); the layout is described
in ``../shared/data/fclib/SOURCE.md``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _core, _validate
from ._assembly import assemble
from .errors import ArgumentTypeError, ProblemFormatError, ProblemTooLargeError, ShapeError

__all__ = [
    "FrictionContactProblem",
    "GlobalFrictionContactProblem",
    "LcpProblem",
    "read_fclib",
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


def _path(path: Any) -> str:
    """``os.fspath(path)``, refusing anything that is not a path with a coulomb error."""
    if not isinstance(path, (str, os.PathLike)):
        raise ArgumentTypeError(f"path must be a str or os.PathLike, got {path!r}")
    p = os.fspath(path)
    if not isinstance(p, str):
        raise ArgumentTypeError(f"path must be a str or os.PathLike of str, got {path!r}")
    return p


def read_siconos_lcp(path: str | os.PathLike[str]) -> LcpProblem:
    """Read a Siconos LCP file (``lcp_*.dat``), dense or sparse-block storage.

    Raises ``FileNotFoundError`` for a missing file and
    :class:`coulomb.errors.ProblemFormatError` for a malformed one.
    """
    M, q = _core.read_siconos_lcp(_path(path))
    return LcpProblem(M=M, q=q, name=os.path.splitext(os.path.basename(os.fspath(path)))[0])


def _name(path: str | os.PathLike[str]) -> str:
    return os.path.splitext(os.path.basename(os.fspath(path)))[0]


@dataclass(frozen=True)
class FrictionContactProblem:
    """A local friction-contact problem ``u = W r + q`` with Coulomb's law at each contact.

    ``W`` is ``(dim nc, dim nc)``: a dense array from :func:`read_siconos_fc`, a
    ``scipy.sparse.csr_matrix`` from :func:`read_fclib`; ``q`` has ``dim nc`` entries (contact
    by contact, normal first) and ``mu`` one per contact. Solve it with
    ``coulomb.contact.solve(p.W, p.q, p.mu, p.dim)`` (a sparse W is densified there for now).
    """

    W: Any
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
    d = _core.read_siconos_fc(_path(path))
    if d["kind"] == "global":
        return GlobalFrictionContactProblem(
            M=d["M"], H=d["H"], q=d["q"], b=d["b"], mu=d["mu"], dim=int(d["dim"]), name=_name(path)
        )
    return FrictionContactProblem(
        W=d["W"], q=d["q"], mu=d["mu"], dim=int(d["dim"]), name=_name(path)
    )


def _dataset(group: Any, key: str, dtype: Any, what: str, path: str) -> NDArray[Any]:
    """A dataset read whole, after checking that its declared size fits the memory budget."""
    ds = group[key]
    size = int(getattr(ds, "size", 0) or 0)
    budget = _core.memory_budget()
    if size * 8 > budget:
        raise ProblemTooLargeError(
            f"{path}: {what} declares {size} entries ({size * 8} bytes), over the memory "
            f"budget of {budget} bytes (coulomb.set_memory_budget raises it)"
        )
    return np.asarray(ds[()], dtype=dtype).reshape(-1)


def _fclib_matrix(group: Any, name: str, path: str) -> Any:
    """A CSparse matrix group of an FCLib file as a scipy.sparse CSR matrix (``nz >= 0``:
    triplets with i = row, p = column; ``nz = -1``: CSC; ``nz = -2``: CSR). The declared
    sizes, counts, index pointers and indices are all checked before scipy sees them (its
    conversions trust them and read out of bounds on a bad index)."""
    import scipy.sparse as sp

    try:
        g = group[name]
        nz = int(_dataset(g, "nz", np.int64, f"matrix {name}'s nz", path)[0])
        m = int(_dataset(g, "m", np.int64, f"matrix {name}'s m", path)[0])
        n = int(_dataset(g, "n", np.int64, f"matrix {name}'s n", path)[0])
        p = _dataset(g, "p", np.int64, f"matrix {name}'s p", path)
        i = _dataset(g, "i", np.int64, f"matrix {name}'s i", path)
        x = _dataset(g, "x", np.float64, f"matrix {name}'s x", path)
    except (KeyError, IndexError, TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, ProblemTooLargeError):
            raise
        raise ProblemFormatError(f"{path}: matrix {name} is missing or malformed: {exc}") from None
    if m < 0 or n < 0:
        raise ProblemFormatError(f"{path}: matrix {name} declares a negative size {m} x {n}")
    budget = _core.memory_budget()
    if (max(m, n) + 1) * 8 > budget:
        raise ProblemTooLargeError(
            f"{path}: matrix {name} declares {m} x {n}: its index pointers alone need "
            f"{(max(m, n) + 1) * 8} bytes, over the memory budget of {budget} bytes"
        )
    where = f"{path}: "
    try:
        if nz >= 0:
            if min(len(p), len(i), len(x)) < nz:
                raise ProblemFormatError(
                    f"{path}: matrix {name} has fewer than nz = {nz} stored entries"
                )
            rows, cols = i[:nz], p[:nz]
            for idx, size, axis in ((rows, m, "row"), (cols, n, "column")):
                if idx.size and (idx.min() < 0 or idx.max() >= size):
                    raise ProblemFormatError(
                        f"{path}: matrix {name} has a {axis} index outside [0, {size})"
                    )
            mat = sp.coo_matrix((x[:nz], (rows, cols)), shape=(m, n)).tocsr()
        elif nz in (-1, -2):
            major, minor = (n, m) if nz == -1 else (m, n)
            ptr, idx = _validate.compressed_indices(f"matrix {name}", p, i, major, minor, where)
            if x.shape[0] < ptr[-1]:
                raise ProblemFormatError(
                    f"{path}: matrix {name} has {x.shape[0]} values for {ptr[-1]} entries"
                )
            kind = sp.csc_matrix if nz == -1 else sp.csr_matrix
            mat = kind((x[: ptr[-1]], idx, ptr), shape=(m, n)).tocsr()
        else:
            raise ProblemFormatError(f"{path}: matrix {name} has an unknown storage nz = {nz}")
        mat.check_format(full_check=True)
    except ShapeError as exc:
        raise ProblemFormatError(str(exc)) from None
    except (ValueError, IndexError) as exc:
        if isinstance(exc, ProblemFormatError):
            raise
        raise ProblemFormatError(f"{path}: matrix {name}: {exc}") from None
    if not np.isfinite(mat.data).all():
        raise ProblemFormatError(f"{path}: matrix {name} has NaN or infinite entries")
    mat.sum_duplicates()
    return mat


def _fclib_vector(group: Any, name: str, n: int, path: str) -> NDArray[np.float64]:
    try:
        v = _dataset(group["vectors"], name, np.float64, f"vector {name}", path)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        if isinstance(exc, ProblemTooLargeError):
            raise
        raise ProblemFormatError(f"{path}: vector {name} is missing or malformed: {exc}") from None
    if v.shape[0] != n:
        raise ProblemFormatError(f"{path}: vector {name} has {v.shape[0]} entries, expected {n}")
    if not np.isfinite(v).all():
        raise ProblemFormatError(f"{path}: vector {name} has NaN or infinite entries")
    return v


def _symmetric_from_triangle(M: Any) -> Any:
    """LMGC90 writes a symmetric M by one triangle only: when every off-diagonal entry lies
    strictly in one triangle, return ``T + T^T - diag(T)``; otherwise M unchanged."""
    import scipy.sparse as sp

    coo = M.tocoo()
    off = coo.row != coo.col
    if not off.any():
        return M
    upper = coo.row[off] < coo.col[off]
    if upper.all() or not upper.any():
        return (M + M.T - sp.diags(M.diagonal())).tocsr()
    return M


def read_fclib(path: str | os.PathLike[str]) -> FrictionContactProblem:
    """Read an FCLib HDF5 friction-contact problem as a local problem ``u = W r + q``.

    - ``/fclib_local``: W as stored (triplet, CSC or CSR), returned as a
      ``scipy.sparse.csr_matrix``; q and mu as stored.
    - ``/fclib_global`` (``M v = H r + f``, ``u = H^T v + w``): reduced to the local problem
      ``W = H^T M^-1 H``, ``q = H^T M^-1 f + w`` by :func:`coulomb.contact.assemble` (Cholesky
      of M in Rust; W returned as CSR). An M stored by one triangle only (as LMGC90 writes it)
      is completed symmetrically first. Global problems with equality constraints (a G
      matrix) are refused.
    - ``/fclib_global_rolling`` (rolling friction) and local problems with equality
      multipliers (V, R) are refused: coulomb does not model them.

    ``dim`` is FCLib's spacedim (2 or 3). The name is the file's stem.

    Raises
    ------
    ImportError
        When h5py (the optional extra ``coulomb[hdf5]``) or scipy is missing.
    FileNotFoundError
        For a missing file.
    coulomb.errors.ProblemFormatError
        For a file that is not a readable FCLib problem, or one of the unsupported kinds above.
    """
    try:
        import h5py
    except ImportError as exc:
        raise ImportError(
            "reading FCLib files needs h5py: install the optional extra, "
            "pip install 'coulomb[hdf5]'"
        ) from exc
    try:
        import scipy.sparse  # noqa: F401
    except ImportError as exc:
        raise ImportError("reading FCLib files needs scipy (pip install scipy)") from exc
    p = _path(path)
    if not os.path.exists(p):
        raise FileNotFoundError(p)
    try:
        f = h5py.File(p, "r")
    except OSError as exc:
        raise ProblemFormatError(f"{p}: not an HDF5 file: {exc}") from None
    try:
        return _read_fclib_file(f, p)
    except (RuntimeError, OSError, KeyError, TypeError, AttributeError) as exc:
        # h5py's own errors on a corrupted file (bad object headers, truncated data, ...)
        raise ProblemFormatError(f"{p}: corrupted or unreadable HDF5 content: {exc}") from None
    finally:
        try:
            f.close()
        except Exception:
            pass


def _read_fclib_file(f: Any, p: str) -> FrictionContactProblem:
    """The body of :func:`read_fclib` on an open file."""
    with f:
        if "fclib_global_rolling" in f:
            raise ProblemFormatError(
                f"{p}: rolling-friction problems (fclib_global_rolling) are not supported"
            )
        kinds = [k for k in ("fclib_local", "fclib_global") if k in f]
        if not kinds:
            raise ProblemFormatError(
                f"{p}: no fclib_local or fclib_global group (found {sorted(f.keys())})"
            )
        kind = kinds[0]
        g = f[kind]
        try:
            dim = int(g["spacedim"][0])
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise ProblemFormatError(f"{p}: spacedim is missing or malformed: {exc}") from None
        if dim not in (2, 3):
            raise ProblemFormatError(f"{p}: spacedim must be 2 or 3, got {dim}")
        if kind == "fclib_local":
            if "V" in g or "R" in g:
                raise ProblemFormatError(
                    f"{p}: local problems with equality multipliers (V, R) are not supported"
                )
            W = _fclib_matrix(g, "W", p)
            m = W.shape[0]
            if W.shape != (m, m) or m % dim != 0:
                raise ProblemFormatError(f"{p}: W has shape {W.shape}, not square of dim * nc")
            q = _fclib_vector(g, "q", m, p)
            mu = _fclib_vector(g, "mu", m // dim, p)
        else:
            if "G" in g:
                raise ProblemFormatError(
                    f"{p}: global problems with equality constraints (G) are not supported"
                )
            M = _fclib_matrix(g, "M", p)
            M = _symmetric_from_triangle(M)
            H = _fclib_matrix(g, "H", p)
            ndof, m = H.shape
            if M.shape != (ndof, ndof) or m % dim != 0:
                raise ProblemFormatError(
                    f"{p}: M {M.shape} and H {H.shape} do not fit (M ndof x ndof, H ndof x dim nc)"
                )
            force = _fclib_vector(g, "f", ndof, p)
            w = _fclib_vector(g, "w", m, p)
            mu = _fclib_vector(g, "mu", m // dim, p)
            import scipy.sparse as sp

            Wd, q = assemble(M, H, force=force, extra=w)
            W = sp.csr_matrix(Wd)
    if (mu < 0).any():
        raise ProblemFormatError(f"{p}: negative friction coefficient")
    return FrictionContactProblem(W=W, q=q, mu=mu, dim=dim, name=_name(p))
