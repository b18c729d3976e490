"""Lemke's two engines (product form and tableau) from Python: the same path and answer
where ties are clear, the default's answers equal an oracle's, and a bad name is refused."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
from coulomb.errors import InvalidParameterError


@pytest.mark.parametrize("n", [20, 90, 200])
def test_engines_follow_the_same_path_on_spd_problems(n):
    rng = np.random.default_rng(n)
    a = rng.standard_normal((n, n))
    M = a @ a.T / n + np.eye(n)
    q = rng.standard_normal(n)
    t = coulomb.lcp.solve(M, q, engine="tableau")
    p = coulomb.lcp.solve(M, q, engine="product_form")
    d = coulomb.lcp.solve(M, q)
    assert t.success and p.success and d.success
    assert t.pivots == p.pivots == d.pivots
    np.testing.assert_array_equal(t.basis, p.basis)
    np.testing.assert_allclose(p.z, t.z, rtol=1e-10, atol=1e-12)
    # the oracle: an SPD LCP has one solution, which PGS reaches to tight tolerance
    ref = coulomb.lcp.solve(M, q, method="pgs", tol=1e-13, max_iter=500_000)
    assert ref.success
    np.testing.assert_allclose(d.z, ref.z, rtol=1e-8, atol=1e-10)


def test_an_unknown_engine_is_refused_before_any_work():
    with pytest.raises(InvalidParameterError, match="engine"):
        coulomb.lcp.solve(np.eye(2), np.array([-1.0, -1.0]), engine="simplex")  # type: ignore[arg-type]
