"""Property tests on PSD problems: whatever Lemke returns is honest, and for PSD M (which is
copositive-plus) a ray termination proves that no solution exists."""

from __future__ import annotations

import os

import numpy as np
from coulomb import lcp
from helpers import lcp_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

# Any bounded float (tiny ones included): honesty must hold whatever the data.
WIDE = st.floats(-10, 10, allow_nan=False, allow_infinity=False, allow_subnormal=False)
# Entries of moderate magnitude: M = A A^T stays PSD to rounding (no underflow to an
# indefinite matrix), so the theorem about copositive-plus matrices applies to the data.
MODERATE = st.one_of(
    st.just(0.0),
    st.integers(-3, 3).map(float),
    st.floats(1e-3, 10),
    st.floats(-10, -1e-3),
)
# derandomized: the examples are the same on every run (CI cannot flake); set
# COULOMB_PROPERTIES=long for a fresh random search with more examples
LONG = os.environ.get("COULOMB_PROPERTIES") == "long"
SETTINGS = settings(
    max_examples=3000 if LONG else 300,
    deadline=None,
    derandomize=not LONG,
    suppress_health_check=[HealthCheck.too_slow],
)


@st.composite
def psd_problems(draw, elements, max_n=12):
    n = draw(st.integers(1, max_n))
    k = draw(st.integers(1, max_n))
    A = draw(arrays(np.float64, (n, k), elements=elements))
    q = draw(arrays(np.float64, (n,), elements=elements)) * 10.0
    M = A @ A.T
    return (M + M.T) / 2, q


@SETTINGS
@given(psd_problems(WIDE), st.sampled_from([1e-12, 1e-9, 1e-6]))
def test_success_is_honest(problem, tol):
    M, q = problem
    r = lcp.solve(M, q, tol=tol)
    assert r.success is False or r.error <= tol
    assert r.success == (r.status == "solved")
    if not r.success:
        return
    # independent recomputation: by coulomb's own checker ...
    c = lcp.check(M, q, r.z)
    assert abs(c.error - r.error) <= 1e-12 * r.error
    # ... and in numpy, up to the rounding of M z + q
    qn = np.linalg.norm(q)
    rounding = 1e-13 * (np.abs(M).max() * np.abs(r.z).max() + np.abs(q).max())
    assert lcp_error(M, q, r.z) <= tol + rounding / max(1.0, qn)
    np.testing.assert_allclose(r.w, M @ r.z + q, rtol=0, atol=rounding)
    assert r.z.min() >= -tol
    assert r.w.min() >= -tol * (1.0 + qn)


@SETTINGS
@given(psd_problems(MODERATE, max_n=8))
def test_ray_means_no_solution_for_psd(problem):
    """Lemke processes copositive-plus LCPs: a secondary ray proves infeasibility, and so a
    problem that enumeration solves must be solved."""
    M, q = problem
    r = lcp.solve(M, q)
    e = lcp.solve(M, q, method="enumerate")
    if r.status == "ray_termination":
        assert len(e.solutions) == 0
    if len(e.solutions) > 0:
        # solved, or (an ill-conditioned basis: M z + q cannot be formed below its rounding)
        # an honest numerical_failure whose answer is right to the rounding of the data
        rounding = 1e-13 * (np.abs(M).max() * np.abs(r.z).max() + np.abs(q).max())
        qn = max(1.0, float(np.linalg.norm(q)))
        assert r.success is True or (
            r.status == "numerical_failure" and r.error <= 1e-9 + rounding / qn
        ), r.message
    if r.success:
        assert r.error <= 1e-9
