"""Seeded, deterministic LCP test problems for the peer benchmarks.

Every generator returns an :class:`LcpProblem` for the linear complementarity
problem: find ``z`` with ``w = M z + q``, ``z >= 0``, ``w >= 0``, ``z . w = 0``.
Only numpy is needed; the Siconos loader needs ``coulomb`` and is optional.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

FAMILY_DENSE_SPD = "dense SPD"
FAMILY_CONTACT_PSD = "contact-like PSD"
FAMILY_SMALL_3X3 = "small 3x3"
FAMILY_SICONOS = "Siconos"


@dataclass(frozen=True)
class LcpProblem:
    """One LCP instance ``(M, q)`` with a label for reports."""

    family: str
    n: int
    M: np.ndarray
    q: np.ndarray
    label: str = ""
    z_planted: np.ndarray | None = None


def lcp_error(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """The project's LCP error: ``||min(z, M z + q)||_2 / max(1, ||q||_2)``."""
    z = np.asarray(z, dtype=np.float64).reshape(-1)
    w = M @ z + q
    residual = float(np.linalg.norm(np.minimum(z, w)))
    return residual / max(1.0, float(np.linalg.norm(q)))


def dense_spd(n: int, seed: int = 0) -> LcpProblem:
    """Dense SPD matrix ``A A^T / n + I`` with a standard normal ``q``."""
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n))
    m = a @ a.T / n + np.eye(n)
    q = rng.standard_normal(n)
    if np.all(q >= 0.0):  # keep the answer non-trivial (z = 0 would solve it)
        q[0] = -abs(q[0]) - 1.0
    return LcpProblem(FAMILY_DENSE_SPD, n, np.ascontiguousarray(m), q, f"seed={seed}")


def contact_psd(
    n: int,
    seed: int = 0,
    rank_ratio: float = 0.5,
    active_fraction: float = 0.5,
) -> LcpProblem:
    """Rank-deficient ``M = J J^T`` (like redundant contacts) with a planted answer.

    ``J`` is ``n x max(1, round(rank_ratio * n))`` standard normal, scaled so
    ``M`` has O(1) entries. A random set of indices gets ``z* > 0`` (``w* = 0``),
    the rest gets ``w* > 0`` (``z* = 0``); then ``q = w* - M z*``.
    """
    rng = np.random.default_rng(seed)
    cols = max(1, round(rank_ratio * n))
    j = rng.standard_normal((n, cols)) / np.sqrt(cols)
    m = j @ j.T
    active = rng.random(n) < active_fraction
    if not active.any():
        active[rng.integers(n)] = True
    z_star = np.where(active, rng.uniform(0.1, 1.0, n), 0.0)
    w_star = np.where(active, 0.0, rng.uniform(0.1, 1.0, n))
    q = w_star - m @ z_star
    return LcpProblem(
        FAMILY_CONTACT_PSD,
        n,
        np.ascontiguousarray(m),
        q,
        f"seed={seed}, rank={cols}, active={int(active.sum())}",
        z_star,
    )


def small_3x3(seed: int = 0) -> LcpProblem:
    """A tiny SPD problem: the per-call overhead case."""
    problem = dense_spd(3, seed)
    return LcpProblem(FAMILY_SMALL_3X3, 3, problem.M, problem.q, problem.label)


def siconos_problem(path: Path) -> LcpProblem:
    """Load a Siconos ``.dat`` LCP through ``coulomb.io.read_siconos_lcp``.

    Raises ``ImportError`` when coulomb is not installed.
    """
    from coulomb.io import read_siconos_lcp

    data = read_siconos_lcp(str(path))
    m = np.ascontiguousarray(data.M, dtype=np.float64)
    q = np.ascontiguousarray(data.q, dtype=np.float64).reshape(-1)
    return LcpProblem(FAMILY_SICONOS, q.shape[0], m, q, Path(path).stem)
