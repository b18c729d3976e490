"""Finite data of extreme magnitude (1e-300 .. 1e300, subnormals): the solver may fail, but
it must say so through ``status``/``success`` - never raise, never claim a false success."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import lcp


@pytest.mark.parametrize(
    "M, q",
    [
        # w1 = 1e160 z2 - 1 >= 0 needs z2 > 0, then w2 = 1e-160 z2 > 0: no solution.
        ([[0.0, 1e160], [0.0, 1e-160]], [-1.0, 0.0]),
        # w2 = b z1 - 1 >= 0 needs z1 >= 1/b, but z1 > 0 forces z1 = 1 - b z2 <= 1.
        ([[1.0, 1e-310], [1e-310, 0.0]], [-1.0, -1.0]),
        ([[1.0, 5e-324], [5e-324, 0.0]], [-1.0, -1.0]),
        ([[2.095566e-16, 3.22103247e-316], [3.22103247e-316, 0.0]], [-1.0, -1.0]),
    ],
)
def test_infeasible_extreme_problems_report_failure(M, q):
    r = lcp.solve(M, q)  # must not raise coulomb.errors.InternalError
    assert r.success is False
    assert r.status != "solved"


@pytest.mark.parametrize("k", [10, 20, 30, 50, 100, 300])
def test_a_tiny_row_cannot_hide_a_wrong_answer(k):
    """Row 1 is ``w1 = s (z1 - 1)`` with s = 10^-k, row 2 is ``w2 = z2 + 1``: the unique
    solution is z = (1, 0). In its own units row 1 is ``z1 - 1``, so z = 0 violates it by 1;
    the scaled error exists to catch exactly this ("a tiny q cannot hide a wrong answer")."""
    s = 10.0**-k
    r = lcp.solve(np.diag([s, 1.0]), [-s, 1.0])
    if r.success:
        np.testing.assert_allclose(r.z, [1.0, 0.0], rtol=1e-9, atol=0)


def test_random_extreme_problems_are_reported_honestly():
    """Entries 10^k with k uniform in [-320, 300]: no exception, and success implies the
    error bound (recomputed independently)."""
    failures = []
    for seed in range(400):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(1, 7))
        A = rng.standard_normal((n, n)) * 10.0 ** rng.integers(-320, 300, (n, n))
        with np.errstate(all="ignore"):
            M = A @ A.T if seed % 2 == 0 else A
        if not np.isfinite(M).all():
            continue
        q = rng.standard_normal(n) * 10.0 ** rng.integers(-320, 300, n)
        try:
            r = lcp.solve(M, q)
        except Exception as exc:
            failures.append(f"seed {seed}: {type(exc).__name__}: {exc}")
            continue
        if r.success:
            assert r.error <= 1e-9, f"seed {seed}"
            assert lcp.check(M, q, r.z).error == pytest.approx(r.error, rel=1e-12, abs=0)
    assert not failures, f"{len(failures)} raised, e.g. " + "; ".join(failures[:3])
