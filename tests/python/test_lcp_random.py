"""Random problems with known answers: P-matrices (unique solution, found by enumeration) and
singular PSD matrices with a planted solution (w is unique even when z is not), unscaled and
badly scaled."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import lcp
from helpers import (
    lcp_error,
    planted_psd,
    pmatrix_diagonally_dominant,
    pmatrix_spd_plus_skew,
    rel_diff,
)

GENERATORS = {"spd+skew": pmatrix_spd_plus_skew, "diag-dominant": pmatrix_diagonally_dominant}
P_SEEDS = range(25)
PSD_CASES = [(n, seed) for n in (5, 30, 100, 300) for seed in range(3)]


def p_problem(kind: str, seed: int):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 11))
    M = GENERATORS[kind](rng, n)
    q = 5.0 * rng.standard_normal(n)
    return rng, M, q


def unique_solution(M, q):
    e = lcp.solve(M, q, method="enumerate")
    assert e.success is True
    assert e.solutions.shape == (1, len(q)), "a P-matrix LCP has exactly one solution"
    assert lcp_error(M, q, e.solutions[0]) <= 1e-10
    return e.solutions[0]


def scalings(rng, M, q):
    """(name, M', q', recover z, recover w) for the scalings the solver must be blind to."""
    n = len(q)
    R = 10.0 ** rng.integers(-6, 7, n)
    C = 10.0 ** rng.integers(-6, 7, n)
    yield "x1e-8", M * 1e-8, q * 1e-8, (lambda z: z), (lambda w: w / 1e-8)
    yield "x1e8", M * 1e8, q * 1e8, (lambda z: z), (lambda w: w / 1e8)
    # M' = R M C, q' = R q: z = C z', w = w' / R
    yield "rows/cols", R[:, None] * M * C[None, :], R * q, (lambda z: C * z), (lambda w: w / R)


@pytest.mark.parametrize("kind", GENERATORS)
@pytest.mark.parametrize("seed", P_SEEDS)
def test_pmatrix_lemke_equals_enumeration(kind, seed):
    _, M, q = p_problem(kind, seed)
    # the generator really makes a P-matrix (all principal minors > 0), checked for n <= 6
    n = len(q)
    if n <= 6:
        for mask in range(1, 2**n):
            idx = [i for i in range(n) if mask >> i & 1]
            assert np.linalg.det(M[np.ix_(idx, idx)]) > 0
    z = unique_solution(M, q)
    r = lcp.solve(M, q)
    assert r.success is True
    assert r.error <= 1e-10
    assert rel_diff(r.z, z) <= 1e-9


@pytest.mark.parametrize("kind", GENERATORS)
@pytest.mark.parametrize("seed", P_SEEDS)
def test_pmatrix_scaling(kind, seed):
    rng, M, q = p_problem(kind, seed)
    z = unique_solution(M, q)
    for name, Ms, qs, z_of, _ in scalings(rng, M, q):
        r = lcp.solve(Ms, qs)
        assert r.success is True, name
        assert rel_diff(z_of(r.z), z) <= 1e-8, name


@pytest.mark.parametrize("n, seed", PSD_CASES)
def test_planted_psd(n, seed):
    rng = np.random.default_rng(1000 * n + seed)
    M, q, z_star, w_star, _ = planted_psd(rng, n)
    assert np.linalg.matrix_rank(M) < n  # singular: z need not be unique
    assert lcp_error(M, q, z_star) <= 1e-12  # the plant is a solution
    r = lcp.solve(M, q)
    assert r.success is True
    assert r.error <= 1e-10
    assert lcp_error(M, q, r.z) <= 1e-10
    assert rel_diff(r.w, w_star) <= 1e-8


@pytest.mark.parametrize("n, seed", PSD_CASES)
def test_planted_psd_scaling(n, seed):
    rng = np.random.default_rng(1000 * n + seed)
    M, q, _, w_star, _ = planted_psd(rng, n)
    for name, Ms, qs, _, w_of in scalings(rng, M, q):
        r = lcp.solve(Ms, qs)
        assert r.success is True, name
        assert rel_diff(w_of(r.w), w_star) <= 1e-8, name
