"""Consecutive solves share one Lemke workspace per thread (for n <= 256): whatever the
previous call left in it, every answer must equal an independent oracle's."""

from __future__ import annotations

import coulomb
import numpy as np


def _spd(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    a = rng.standard_normal((n, n))
    return a @ a.T / n + np.eye(n), rng.standard_normal(n)


def test_alternating_sizes_match_the_oracles():
    rng = np.random.default_rng(7)
    # sizes that grow, shrink and repeat, around the blocked-update threshold (64) and past
    # the reuse bound (256), so every transition of the shared workspace is exercised
    for n in (3, 8, 3, 70, 8, 300, 5, 70, 1, 9):
        M, q = _spd(rng, n)
        got = coulomb.lcp.solve(M, q)
        assert got.success, (n, got.message)
        if n <= 10:
            # a P-matrix LCP has exactly one solution: enumeration finds it
            want = coulomb.lcp.solve(M, q, method="enumerate").solutions
            assert want.shape[0] == 1
            np.testing.assert_allclose(got.z, want[0], rtol=1e-10, atol=1e-12)
        else:
            want = coulomb.lcp.solve(M, q, method="pgs", tol=1e-13, max_iter=200_000)
            assert want.success
            np.testing.assert_allclose(got.z, want.z, rtol=1e-8, atol=1e-10)


def test_a_failed_solve_leaves_the_next_one_correct():
    # a ray termination stops mid-path with the workspace in an arbitrary state
    bad = coulomb.lcp.solve(np.array([[-1.0, 0.0], [0.0, -1.0]]), np.array([-1.0, -1.0]))
    assert bad.status == "ray_termination"
    good = coulomb.lcp.solve(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-3.0, -3.0]))
    np.testing.assert_allclose(good.z, [1.0, 1.0], atol=1e-14)
    np.testing.assert_allclose(good.w, [0.0, 0.0], atol=1e-14)
