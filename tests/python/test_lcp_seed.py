"""The seed chapter's two scalar LCPs (Satici ch. 11, after Stewart 2000)."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import lcp


def test_scalar_lcp_with_solution():
    # w = 2 z - 6: the chapter's answer is z = 3, w = 0.
    r = lcp.solve([[2]], [-6])
    assert r.status == "solved"
    assert r.success is True
    assert r.z.shape == (1,)
    assert r.z[0] == pytest.approx(3.0, abs=1e-12)
    assert r.w[0] == pytest.approx(0.0, abs=1e-12)
    assert r.error <= 1e-12


def test_scalar_lcp_without_solution_reports_ray():
    # w = -z - 1 < 0 for every z >= 0: no solution; reported, not raised.
    r = lcp.solve([[-1]], [-1])
    assert r.status == "ray_termination"
    assert r.success is False
    # The answer returned must not pass for a solution: w = -z - 1 <= -1.
    assert r.w[0] == pytest.approx(-r.z[0] - 1.0, abs=1e-12)
    assert r.error > 0.5


@pytest.mark.parametrize("a, b", [(2.0, -6.0), (0.5, -3.0), (4.0, 1.0), (1e-3, -2e-3)])
def test_scalar_lcp_analytic(a, b):
    # For a > 0 the unique solution is z = max(0, -b / a).
    r = lcp.solve([[a]], [b])
    assert r.success is True
    assert r.z[0] == pytest.approx(max(0.0, -b / a), rel=1e-14, abs=1e-300)
    assert r.w[0] == pytest.approx(max(0.0, b), rel=1e-14, abs=1e-12)


def test_enumeration_agrees_on_the_seed():
    r = lcp.solve([[2.0]], [-6.0], method="enumerate")
    assert r.success is True
    np.testing.assert_allclose(r.solutions, [[3.0]], rtol=1e-14)
    e = lcp.solve([[-1.0]], [-1.0], method="enumerate")
    assert e.success is False
    assert e.status == "no_solution"
    assert len(e.solutions) == 0
