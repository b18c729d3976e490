"""Problem generators, independent error measures and the data lookup for the tests."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

Array = NDArray[np.float64]

# ---- where the benchmark data is ------------------------------------------------------------
#
# The small sets ship in tests/data (the Siconos LCP set, the Siconos friction-contact files of
# at most 200 kB, seven FCLib files); the full sets are in $COULOMB_DATA or ../shared/data
# beside the checkout. A file is looked up in tests/data first. A test whose data is absent is
# skipped with the reason, except when COULOMB_DATA or CI is set: then the data must be there
# and its absence fails the test.

#: tests/data: the data that ships with the repository.
SHIPPED = Path(__file__).resolve().parents[1] / "data"


def external_data_dir() -> Path:
    """``$COULOMB_DATA`` if set, else ``<checkout>/../shared/data``."""
    env = os.environ.get("COULOMB_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3] / "shared" / "data"


def data_required() -> bool:
    """True when the full data must be present: ``COULOMB_DATA`` or ``CI`` is set."""
    ci = os.environ.get("CI", "").strip().lower()
    return bool(os.environ.get("COULOMB_DATA")) or ci not in ("", "0", "false", "no")


def missing_data(reason: str) -> None:
    """Skips the test with the reason, or fails it when the data is required."""
    if data_required():
        pytest.fail(f"{reason} (COULOMB_DATA or CI is set, so the data must be there)")
    pytest.skip(f"{reason}; set COULOMB_DATA to the benchmark data folder")


def shipped_dir(set_name: str) -> Path:
    """``tests/data/<set_name>``; fails if it is not there (it is part of the repository)."""
    path = SHIPPED / set_name
    if not path.is_dir():
        pytest.fail(f"shipped test data missing: {path}")
    return path


def full_set_dir(set_name: str) -> Path:
    """The full set in ``$COULOMB_DATA`` or ``../shared/data`` (skips or fails if absent)."""
    path = external_data_dir() / set_name
    if not path.is_dir():
        missing_data(f"the full {set_name} set is not at {path}")
    return path


def has_full_set(set_name: str) -> bool:
    return (external_data_dir() / set_name).is_dir()


def data_file(set_name: str, name: str) -> Path:
    """A file of a set (``name`` relative to the set's folder): the shipped copy if there is
    one, else the full set's (skips or fails when neither exists)."""
    shipped = SHIPPED / set_name / name
    if shipped.is_file():
        return shipped
    path = external_data_dir() / set_name / name
    if not path.is_file():
        missing_data(f"{set_name}/{name} is not shipped in tests/data and not at {path}")
    return path


def available_dir(set_name: str) -> tuple[Path, bool]:
    """The full set if present (or required), else the shipped subset; and whether it is the
    full set."""
    if has_full_set(set_name) or data_required():
        return full_set_dir(set_name), True
    return shipped_dir(set_name), False


class ProblemSet(Mapping[str, Any]):
    """Problems of a data set by name, read on first use: an item is looked up in tests/data
    first (a missing one skips or fails the test that asks for it); iterating covers the full
    set, so a test that goes through every problem needs it."""

    def __init__(
        self,
        set_name: str,
        reader: Callable[[Path], Any],
        suffix: str = ".dat",
        exclude: tuple[str, ...] = (),
    ) -> None:
        self.set_name, self.reader, self.suffix, self.exclude = set_name, reader, suffix, exclude
        self._cache: dict[str, Any] = {}

    def __getitem__(self, name: str) -> Any:
        if name not in self._cache:
            self._cache[name] = self.reader(data_file(self.set_name, name + self.suffix))
        return self._cache[name]

    def names(self) -> list[str]:
        folder = full_set_dir(self.set_name)
        return sorted(
            f.name[: -len(self.suffix)]
            for f in folder.glob("*" + self.suffix)
            if f.name[: -len(self.suffix)] not in self.exclude
        )

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self.names())


def lcp_error(M: Array, q: Array, z: Array) -> float:
    """``||min(z, M z + q)||_2 / max(1, ||q||_2)``, recomputed here in numpy."""
    w = M @ z + q
    return float(np.linalg.norm(np.minimum(z, w)) / max(1.0, np.linalg.norm(q)))


def rel_diff(a: Array, b: Array) -> float:
    """``||a - b||_inf / ||b||_inf`` (absolute when b = 0)."""
    scale = float(np.abs(b).max(initial=0.0))
    diff = float(np.abs(np.asarray(a) - np.asarray(b)).max(initial=0.0))
    return diff / scale if scale > 0 else diff


def pmatrix_spd_plus_skew(rng: np.random.Generator, n: int) -> Array:
    """S + K with S symmetric positive definite and K skew: M + M^T = 2 S > 0, so M is P."""
    A = rng.standard_normal((n, n))
    S = A @ A.T + 0.1 * np.eye(n)
    B = rng.standard_normal((n, n))
    return S + (B - B.T)


def pmatrix_diagonally_dominant(rng: np.random.Generator, n: int) -> Array:
    """Strictly row-diagonally-dominant with a positive diagonal: a P-matrix."""
    A = rng.standard_normal((n, n))
    np.fill_diagonal(A, 0.0)
    diag = np.abs(A).sum(axis=1) + 0.1 + rng.random(n)
    return A + np.diag(diag)


def spd(rng: np.random.Generator, n: int, shift: float = 0.1) -> Array:
    A = rng.standard_normal((n, n))
    M = A @ A.T / n + shift * np.eye(n)
    return (M + M.T) / 2


def planted(
    rng: np.random.Generator, M: Array, active_fraction: float = 0.5
) -> tuple[Array, Array, Array, NDArray[np.bool_]]:
    """A q whose LCP(M, q) has the solution z* (>= 0 on a random active set) with w* >= 0
    complementary: ``q = w* - M z*``. Returns q, z*, w*, active."""
    n = M.shape[0]
    active = rng.random(n) < active_fraction
    if n > 1 and active.all():
        active[rng.integers(n)] = False
    if n > 1 and not active.any():
        active[rng.integers(n)] = True
    z = np.where(active, 0.1 + rng.random(n), 0.0)
    w = np.where(active, 0.0, 0.1 + rng.random(n))
    return w - M @ z, z, w, active


def planted_psd(
    rng: np.random.Generator, n: int
) -> tuple[Array, Array, Array, Array, NDArray[np.bool_]]:
    """Singular PSD ``M = J J^T`` (J is n x m, m < n) with a planted solution.
    Returns M, q, z*, w*, active."""
    m = max(1, n // 3)
    J = rng.standard_normal((n, m))
    M = J @ J.T
    M = (M + M.T) / 2
    q, z, w, active = planted(rng, M)
    return M, q, z, w, active


def project_coulomb_cone(v: Array, mu: float) -> Array:
    """The Euclidean projection of one contact's v = (normal, tangents...) on
    ``{||t|| <= mu n}``, by the textbook three cases (numpy only)."""
    vn, vt = float(v[0]), np.asarray(v[1:], dtype=float)
    t = float(np.linalg.norm(vt))
    if mu * t <= -vn:  # in the polar cone
        return np.zeros_like(v, dtype=float)
    if t <= mu * vn:  # already in the cone
        return np.array(v, dtype=float)
    a = (vn + mu * t) / (1.0 + mu * mu)
    return np.concatenate([[a], mu * a * vt / t])


def contact_error(W: Array, q: Array, mu: Array, dim: int, r: Array) -> tuple[float, float]:
    """De Saxce's natural-map residual ``||r - P_K(r - (u + mu ||u_t|| n))||`` of impulses r
    (any shape with dim nc entries) with ``u = W r + q``, divided by
    ``max(||q||, ||r||, ||u||)`` and by ``||q||``: the (error, error_q) pair of DESIGN.md,
    recomputed here in numpy."""
    r = np.asarray(r, dtype=float).reshape(-1)
    q = np.asarray(q, dtype=float)
    u = np.asarray(W, dtype=float) @ r + q
    res = np.empty_like(r)
    for i, m in enumerate(np.broadcast_to(mu, (r.size // dim,))):
        s = slice(i * dim, (i + 1) * dim)
        ri, ui = r[s], u[s]
        v = ri - ui
        v[0] -= m * np.linalg.norm(ui[1:])
        res[s] = ri - project_coulomb_cone(v, float(m))
    norm = float(np.linalg.norm(res))
    denom = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    denom = denom if denom >= 1e-300 else 1.0
    qn = float(np.linalg.norm(q))
    return norm / denom, norm / (qn if qn >= 1e-300 else 1.0)


def contact_scaled_error(W: Array, q: Array, mu: Array, dim: int, r: Array) -> float:
    """The unit-consistent measure that decides ``success`` (coulomb.contact's module notes),
    recomputed here in numpy for isotropic friction: with ``rho_i = 1 / W_nn,i`` (the mean
    positive ``W_nn`` for a contact whose own is not positive or below 1e-12 times it), the
    worst contact's larger of De Saxce's and Alart-Curnier's natural maps in impulse units,
    relative to ``max(||r_i||, rho_i ||(|W| |r| + |q|)_i||)``; in De Saxce's map the slip
    ``s = ||u_t||`` counts above its rounding ``f = (n + 3) eps ||(|W| |r| + |q|)_t||``, as
    ``s - f^2 / s`` (0 below f)."""
    r = np.asarray(r, dtype=float).reshape(-1)
    q = np.asarray(q, dtype=float)
    W = np.asarray(W, dtype=float)
    nc = r.size // dim
    u = W @ r + q
    terms = np.abs(W) @ np.abs(r) + np.abs(q)
    diag = np.array([W[i * dim, i * dim] for i in range(nc)])
    pos = diag[diag > 0]
    mean = float(pos.mean()) if pos.size else 0.0
    if mean > 0:
        rho = 1.0 / np.where(diag > 1e-12 * mean, diag, mean)
    else:
        rn, qn = np.linalg.norm(r), np.linalg.norm(q)
        rho = np.full(nc, rn / qn if rn > 0 and qn > 0 else 1.0)
    worst = 0.0
    for i, m in enumerate(np.broadcast_to(mu, (nc,))):
        s = slice(i * dim, (i + 1) * dim)
        ri, su = r[s], rho[i] * u[s]
        v = ri - su
        floor = (r.size + 3) * np.finfo(float).eps * np.linalg.norm(terms[s][1:])
        slip = float(np.linalg.norm(u[s][1:]))
        v[0] -= m * rho[i] * (0.0 if slip <= floor else slip - floor * (floor / slip))
        ds = ri - project_coulomb_cone(v, float(m))
        x = ri[1:] - su[1:]
        radius = m * max(ri[0], 0.0)
        nx = np.linalg.norm(x)
        ac = np.concatenate([[ri[0] - max(0.0, ri[0] - su[0])],
                             ri[1:] - (x if nx <= radius else x * (radius / nx))])
        err = max(np.linalg.norm(ds), np.linalg.norm(ac))
        size = max(np.linalg.norm(ri), rho[i] * np.linalg.norm(terms[s]))
        worst = max(worst, err / size if size > 0 else err)
    return float(worst)


def count_during(call):
    """Runs ``call()`` in a thread while this thread counts; returns its result and the count
    made while it ran. With a short switch interval a thread that holds the GIL through a long
    C call lets the counting thread in only at its few bytecode boundaries (calibration on this
    machine: a GIL-holding call of similar length let it count to at most ~600); a call that
    releases the GIL lets it count to 100 000 - 200 000."""
    import sys
    import threading

    counter = [0]
    seen = {}

    def run():
        seen["before"] = counter[0]
        seen["result"] = call()
        seen["after"] = counter[0]

    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        t = threading.Thread(target=run)
        t.start()
        while t.is_alive():
            counter[0] += 1
        t.join()
    finally:
        sys.setswitchinterval(old)
    return seen["result"], seen["after"] - seen["before"]
