"""Lemke's pivot path against an exact-arithmetic Lemke (exact_lemke.py) and Murty's
exponential family, whose pivot count (2^n) and answer (2^n e_n) are known analytically."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from coulomb import lcp
from exact_lemke import lemke as exact_lemke
from exact_lemke import murty


def _exactly_complementary(res) -> bool:
    return (
        min(res.z) >= 0
        and min(res.w) >= 0
        and sum(a * b for a, b in zip(res.z, res.w, strict=True)) == 0
    )


def test_exact_oracle_on_the_seed():
    res = exact_lemke([[2]], [-6])
    assert res.status == "solved"
    assert res.z == [Fraction(3)] and res.w == [Fraction(0)]
    assert res.pivots == 2
    assert exact_lemke([[-1]], [-1]).status == "ray_termination"
    # q >= 0: z = 0 without a pivot.
    res = exact_lemke([[1, 2], [3, 4]], [0, 5])
    assert (res.status, res.pivots, res.z) == ("solved", 0, [0, 0])


@pytest.mark.parametrize("n", range(1, 9))
def test_exact_oracle_on_murty(n):
    M, q = murty(n)
    res = exact_lemke(M, q)
    assert res.status == "solved"
    assert res.pivots == 2**n
    assert res.z == [0] * (n - 1) + [2**n]
    assert _exactly_complementary(res)


@pytest.mark.parametrize("n", range(2, 9))
def test_murty_family_takes_2_to_the_n_pivots(n):
    M, q = murty(n)
    Ma = np.array(M, dtype=float)
    qa = np.array(q, dtype=float)
    # the family's definition, independently of the helper
    assert np.array_equal(Ma, np.eye(n) + 2 * np.triu(np.ones((n, n)), 1))
    assert np.array_equal(qa, [-(2.0 ** (n + 1) - 2.0 ** (i + 1)) for i in range(n)])
    r = lcp.solve(Ma, qa, covering_vector=np.ones(n))
    assert r.pivots == 2**n
    assert r.success is True
    expected_z = np.zeros(n)
    expected_z[-1] = 2.0**n
    np.testing.assert_allclose(r.z, expected_z, atol=1e-12 * 2**n)
    # and the default (equilibrated covering vector) still solves it
    d = lcp.solve(Ma, qa)
    assert d.success is True
    np.testing.assert_allclose(d.z, expected_z, atol=1e-12 * 2**n)


@pytest.mark.parametrize("n", range(2, 7))
def test_murty_path_matches_exact(n):
    M, q = murty(n)
    res = exact_lemke(M, q)
    r = lcp.solve(np.array(M, float), np.array(q, float), covering_vector=np.ones(n))
    assert r.pivots == res.pivots
    assert sorted(r.basis.tolist()) == res.basis


def test_random_integer_problems_follow_the_exact_path():
    """Small integer data is full of ties (degenerate bases): coulomb's lexicographic rule with
    covering vector ones must reproduce the exact path - status, pivot count and answer."""
    for seed in range(300):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(1, 7))
        M = rng.integers(-3, 4, (n, n)).astype(float)
        q = rng.integers(-3, 4, n).astype(float)
        ex = exact_lemke(M.tolist(), q.tolist())
        r = lcp.solve(M, q, covering_vector=np.ones(n))
        context = f"seed {seed}: M = {M.tolist()}, q = {q.tolist()}"
        assert r.status == ex.status, context
        assert r.pivots == ex.pivots, context
        if ex.status == "solved":
            assert _exactly_complementary(ex), context
            assert r.success is True, context
            np.testing.assert_allclose(r.z, [float(x) for x in ex.z], atol=1e-9, err_msg=context)
        else:
            assert r.success is False, context


def test_random_integer_psd_problems_follow_the_exact_path():
    """PSD (copositive-plus): the exact Lemke's ray is a proof of infeasibility."""
    for seed in range(150):
        rng = np.random.default_rng(10_000 + seed)
        n = int(rng.integers(1, 7))
        A = rng.integers(-2, 3, (n, int(rng.integers(1, n + 1)))).astype(float)
        M = A @ A.T
        q = rng.integers(-3, 4, n).astype(float)
        ex = exact_lemke(M.tolist(), q.tolist())
        r = lcp.solve(M, q, covering_vector=np.ones(n))
        context = f"seed {seed}: M = {M.tolist()}, q = {q.tolist()}"
        assert (r.status, r.pivots) == (ex.status, ex.pivots), context
        e = lcp.solve(M, q, method="enumerate")
        assert (len(e.solutions) > 0) == (ex.status == "solved"), context
