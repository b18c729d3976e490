"""The Rust core releases the GIL while it solves."""

from __future__ import annotations

import numpy as np
from coulomb import lcp
from helpers import GIL_RELEASED, count_during


def test_lemke_releases_the_gil():
    rng = np.random.default_rng(0)
    n = 800
    A = rng.standard_normal((n, n))
    M = A @ A.T / n + np.eye(n)  # dense SPD
    q = rng.standard_normal(n)
    # the arrays are already float64 and C-contiguous: solve() does almost no Python work
    r, count = count_during(lambda: lcp.solve(M, q))
    assert r.success is True
    assert r.error <= 1e-10
    assert count > GIL_RELEASED
