"""Warm start: a correct guessed basis solves without a pivot; a wrong one costs nothing but
the cold solve."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import lcp
from helpers import planted, planted_psd, rel_diff, spd


def perturbed_planted(seed: int, n: int):
    """An SPD problem with a planted solution, and the same problem with z*, w* perturbed by
    up to 0.1 % on their supports (the active set, hence the optimal basis, is unchanged)."""
    rng = np.random.default_rng(seed)
    M = spd(rng, n, shift=0.5)
    q, z, w, active = planted(rng, M)
    z2 = z * (1.0 + 1e-3 * rng.random(n))
    w2 = w * (1.0 + 1e-3 * rng.random(n))
    return M, q, M, w2 - M @ z2, z2, active


def as_guess(kind: str, r, n: int):
    if kind == "result":
        return r
    if kind == "basis":
        return r.basis
    mask = np.zeros(n, dtype=bool)
    mask[r.basis] = True
    return mask


@pytest.mark.parametrize("kind", ["result", "basis", "mask"])
@pytest.mark.parametrize("seed, n", [(0, 5), (1, 30), (2, 100)])
def test_accepted_warm_start(seed, n, kind):
    M, q, M2, q2, z2, active = perturbed_planted(seed, n)
    r = lcp.solve(M, q)
    assert r.success is True
    assert sorted(r.basis.tolist()) == np.flatnonzero(active).tolist()
    cold = lcp.solve(M2, q2)
    assert cold.success is True
    assert cold.warm_start == "none"
    assert cold.pivots > 0
    warm = lcp.solve(M2, q2, warm_start=as_guess(kind, r, n))
    assert warm.warm_start == "accepted"
    assert warm.pivots == 0
    assert warm.pivots_saved >= len(r.basis) + 1
    assert warm.success is True
    assert warm.error <= 1e-10
    assert rel_diff(warm.z, cold.z) <= 1e-10
    assert rel_diff(warm.z, z2) <= 1e-8
    assert sorted(warm.basis.tolist()) == sorted(cold.basis.tolist())


@pytest.mark.parametrize("seed, n", [(3, 6), (4, 40)])
def test_rejected_warm_start(seed, n):
    _, _, M2, q2, z2, active = perturbed_planted(seed, n)
    wrong = np.flatnonzero(~active)  # the complement of the right basis
    assert len(wrong) > 0
    r = lcp.solve(M2, q2, warm_start=wrong)
    assert r.warm_start == "rejected"
    assert r.success is True
    assert r.pivots > 0
    assert rel_diff(r.z, z2) <= 1e-8


def test_warm_start_on_a_singular_psd_problem():
    # z is not unique here; w is. The previous basis still solves the perturbed problem
    # exactly when the perturbation keeps the plant's structure.
    rng = np.random.default_rng(11)
    M, q, _, w_star, _ = planted_psd(rng, 30)
    r = lcp.solve(M, q)
    assert r.success is True
    again = lcp.solve(M, q, warm_start=r)
    assert again.warm_start == "accepted"
    assert again.pivots == 0
    assert rel_diff(again.w, w_star) <= 1e-8


def test_empty_guess_when_q_is_nonnegative():
    M = spd(np.random.default_rng(5), 4)
    q = np.array([1.0, 0.0, 2.0, 3.0])
    r = lcp.solve(M, q, warm_start=np.array([], dtype=int))
    assert r.success is True
    np.testing.assert_array_equal(r.z, np.zeros(4))
    assert r.pivots == 0
