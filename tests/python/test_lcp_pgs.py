"""Projected Gauss-Seidel / SOR against Lemke on SPD problems (unique solution)."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import lcp
from helpers import lcp_error, planted, rel_diff, spd


def spd_problem(seed: int, n: int):
    rng = np.random.default_rng(seed)
    M = spd(rng, n, shift=0.5)
    q, z_star, _, _ = planted(rng, M)
    return M, q, z_star


@pytest.mark.parametrize("relaxation", [1.0, 1.5])
@pytest.mark.parametrize("seed, n", [(0, 5), (1, 20), (2, 50)])
def test_pgs_reaches_the_lemke_answer(seed, n, relaxation):
    M, q, z_star = spd_problem(seed, n)
    ref = lcp.solve(M, q)
    assert ref.success is True
    assert rel_diff(ref.z, z_star) <= 1e-9  # SPD: the planted solution is the solution
    r = lcp.solve(M, q, method="pgs", tol=1e-10, relaxation=relaxation)
    assert r.status == "solved"
    assert r.success is True
    assert r.error <= 1e-10
    assert lcp_error(M, q, r.z) <= 1e-10
    assert rel_diff(r.z, ref.z) <= 1e-7
    assert r.iterations >= 1


def test_pgs_from_an_initial_point():
    M, q, z_star = spd_problem(3, 10)
    r = lcp.solve(M, q, method="pgs", tol=1e-10, initial=z_star)
    assert r.success is True
    assert rel_diff(r.z, z_star) <= 1e-7


def test_pgs_iteration_limit_is_reported():
    # Ill-conditioned: M = A A^T + 1e-6 I with A of rank n / 2; two sweeps cannot converge.
    rng = np.random.default_rng(7)
    n = 20
    A = rng.standard_normal((n, n // 2))
    M = A @ A.T + 1e-6 * np.eye(n)
    q = rng.standard_normal(n)
    assert np.linalg.cond(M) > 1e6
    r = lcp.solve(M, q, method="pgs", max_iter=2)
    assert r.status == "iteration_limit"
    assert r.success is False
    assert r.error > 0
    assert r.error > 1e-9  # it is not a converged answer mislabelled
    assert r.error == pytest.approx(lcp_error(M, q, r.z), rel=1e-9)
    assert r.iterations == 2


def test_pgs_on_a_diagonal_problem_is_exact():
    # diag(d) z + q: z_i = max(0, -q_i / d_i), reached in one sweep.
    d = np.array([1.0, 2.0, 4.0, 8.0])
    q = np.array([-1.0, 3.0, -2.0, -8.0])
    r = lcp.solve(np.diag(d), q, method="pgs", tol=1e-12)
    assert r.success is True
    np.testing.assert_allclose(r.z, np.maximum(0.0, -q / d), rtol=1e-14, atol=0)
