"""Property suite of coulomb.contact.solve: every reported success is checked by an
independent test of Coulomb's law (contact_gen.law_violation, written from the law, not from
coulomb's measures), on generated problems of known classes (planted solutions: separating,
sticking and sliding contacts; random problems that may have no solution), both dims, units
10^-8..10^8 for impulses and velocities independently, mu 0..1e12.

Profiles: the default is short (CI). ``COULOMB_PROPERTIES=long`` runs the long one (see
docs/properties.md for its counts and the command).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from contact_gen import (
    FALSE,
    METHODS,
    MODERATE_MU,
    TOL,
    campaign,
    generate,
    law_violation,
    perturb_ulp,
    solve,
)
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

LONG = os.environ.get("COULOMB_PROPERTIES") == "long"
SETTINGS = settings(max_examples=1000 if LONG else 25, deadline=None, derandomize=not LONG,
                    suppress_health_check=[HealthCheck.too_slow])
UNITS = st.integers(-8, 8)


@SETTINGS
@given(st.integers(0, 2**31), st.sampled_from([2, 3]), st.booleans(), UNITS, UNITS,
       st.sampled_from(METHODS))
def test_every_success_satisfies_the_law(seed, dim, planted, ka, kb, method):
    p = generate(seed, dim, planted, ka, kb)
    r = solve(p, method)
    assert r.success == (r.status == "solved")
    if r.success:
        v = law_violation(p.W, p.q, p.mu, dim, r.impulse, polygon=method == "lemke" and dim == 3)
        assert v <= FALSE, (r.message, v)


@SETTINGS
@given(st.integers(0, 2**31), st.sampled_from([2, 3]), UNITS, UNITS, st.sampled_from(METHODS))
@example(134217727, 3, 0, 2, "nsgs")  # found by the long profile: a rounding-decided status
def test_status_is_invariant_under_units(seed, dim, ka, kb, method):
    # Planted problems (a solution exists) with mu up to 10. Beyond, a problem is conditioned
    # like mu, and on problems without a solution an iterative method's path is chaotic: a
    # verdict near the tolerance may then flip with the rounding of the scaled data (bounded
    # by the campaign test below, counted in docs/properties.md), never into a false success.
    # The robust mode in 3D is held to it since its polyhedral finish (3000 such problems:
    # 1 status change with the units and 2 with one ulp of the data, against 21 and 28 before;
    # `python contact_gen.py 3000 --moderate`).
    base = generate(seed, dim, True, mu_choices=MODERATE_MU)
    other = generate(seed, dim, True, ka, kb, mu_choices=MODERATE_MU)
    r, s = solve(base, method), solve(other, method)
    if method != "lemke" and r.status != s.status:
        # an iterative method converging at the edge of its budget (NSGS on singular W,
        # campaign seed 1345: solved in 1926 sweeps in some units, 2.6e-8 after 2000 in
        # others): the other run stopped at the limit, this one used most of it
        done, stopped = (r, s) if r.success else (s, r)
        budget = 2000 if method == "nsgs" else 200
        assert done.success and stopped.status == "iteration_limit", (r.message, s.message)
        if done.iterations < 0.75 * budget:
            # or a status that the rounding of the data decides, in the same units: one of six
            # one-ulp perturbations of the base changes it too (NSGS on seed 134217727: solved
            # in 866 sweeps as given, stopped at 2000 with 1.6e-5 in the units (0, 2) and in 4
            # of the 6 perturbations, solved in 579 and 1334 sweeps in the other 2)
            others = {solve(perturb_ulp(base, k), method).status for k in range(6)}
            assert others != {r.status}, (r.message, s.message)
        return
    assert (r.success, r.status) == (s.success, s.status), (r.message, s.message)
    unique = np.linalg.cond(base.W) < 1e6 and base.mu.max() <= 0.5
    if r.success and unique:
        # the answer scales, to the tolerance's precision (the solves run on differently
        # rounded data), relative to the problem's impulse scale
        diag = float(np.abs(np.diag(base.W)).max())
        scale = max(float(np.abs(r.impulse).max()), float(np.abs(base.q).max()) / diag)
        assert np.abs(s.impulse / 10.0**ka - r.impulse).max() <= 1e-6 * scale


@pytest.mark.parametrize("k", [-600, -40, -3, 5, 90, 700])
@pytest.mark.parametrize("method", METHODS)
def test_power_of_two_units_scale_the_answer_exactly(method, k):
    # impulses times 2^k, velocities unchanged: the solver sees the same normalized problem
    p = generate(7, 2, True)
    r = solve(p, method)
    s = solve(generate(7, 2, True) if k == 0 else type(p)(p.W * 2.0**-k, p.q, p.mu, 2, True,
                                                       None), method)
    assert (r.status, r.iterations) == (s.status, s.iterations)
    np.testing.assert_array_equal(s.impulse, r.impulse * 2.0**k)


def test_campaign_has_no_false_success_and_solves_planted_problems():
    counts = campaign(300 if LONG else 30, ulp=True)
    for method, c in counts.items():
        assert c.false_successes == 0, (method, c)
        # planted, mu up to 10: one in 200 at most (long campaign: 0, 0 and 0 in 581, see
        # docs/properties.md; an iterative method may converge at the edge of its budget)
        assert c.status_changes <= 1 + 0.005 * (c.cases - c.hard_cases), (method, c)
        # mu up to 1e12 or no solution planted: 3 in 100 at most (long campaign: 10, 19 and
        # 3 in 2419)
        assert c.hard_status_changes <= 1 + 0.03 * c.hard_cases, (method, c)
        # the rounding control: a change of units changes a status hardly more often than
        # moving the data by one ulp in their own units does (long campaign: 10 / 3, 19 / 14
        # and 3 / 3), so no part of a method depends on the units beyond the rounding of the
        # normalized data and the verdict's error_q half, which is the caller's figure by
        # definition: an iterative method at its budget may pass it in one unit system and
        # not in another (one in 100 allowed for that); the margin of 3 is for the sampling
        # of a few rare events
        units = c.status_changes + c.hard_status_changes
        ulps = c.ulp_status_changes + c.ulp_hard_status_changes
        assert units <= 3 + 2 * ulps + 0.01 * c.cases, (method, c)
    # planted problems (a solution exists) with mu up to 10: Lemke's pivoting (exact in 2D)
    # and the robust mode solve them (long campaign: 100% and 100%, docs/properties.md); with
    # mu up to 1e12 as well, 99.8% and 97% (the robust mode's 3D polyhedral finish); NSGS may
    # stall on singular W
    lemke, prox = counts["lemke"], counts["prox"]
    assert lemke.planted_moderate_successes >= 0.97 * lemke.planted_moderate, lemke
    assert prox.planted_moderate_successes >= 0.97 * prox.planted_moderate, prox
    assert lemke.planted_successes >= 0.85 * lemke.planted, lemke
    assert prox.planted_successes >= 0.9 * prox.planted, prox
    assert TOL == 1e-8


def test_the_robust_mode_solves_planted_3d_problems_through_its_polyhedral_finish():
    # planted 3D problems with mu <= 10 (a solution exists): Newton stalls on about one in
    # five (singular W), and the polyhedral LCP's answer ends the solve or restarts Newton
    # (docs/properties.md: 8 unsolved in 3000 such problems, about 54 before the finish)
    rng = np.random.default_rng(5)
    unsolved = through_polygon = 0
    for _ in range(500):
        p = generate(int(rng.integers(0, 2**31)), 3, True, mu_choices=MODERATE_MU)
        r = solve(p, "prox")
        through_polygon += "polyhedral LCP" in r.message
        if not r.success:
            unsolved += 1
            continue
        assert law_violation(p.W, p.q, p.mu, 3, r.impulse) <= FALSE, r.message
    assert unsolved <= 4, unsolved
    assert through_polygon >= 25, through_polygon


@pytest.mark.parametrize("sliding", [False, True])
def test_lemke_with_a_huge_mu_solves_in_every_unit_system_and_never_falsely(sliding):
    # mu 1e6..1e12 on every contact, both dims, units 10^-8..10^8: planted sticking and
    # separating contacts (and sliding ones, ||r_t|| = mu r_n); each success checked by the
    # independent law check. Lemke's paths on such LCPs fail in some roundings; the capped
    # and scaled LCPs (rust/contact/polyhedral_large_mu.rs) solve most of the rest (here 60
    # and 59 of 60 solved, 198 and 198 of 200 in the long profile; on 1500 other such
    # problems 5 and 8 of 750 unsolved; no false success)
    rng = np.random.default_rng(11 + sliding)
    cases = 200 if LONG else 60
    solved = 0
    for _ in range(cases):
        seed = int(rng.integers(0, 2**31))
        dim = int(rng.choice([2, 3]))
        ka, kb = (int(k) for k in rng.integers(-8, 9, 2))
        mu = float(rng.choice([1e6, 1e8, 1e10, 1e12]))
        p = generate(seed, dim, True, ka, kb, mu_class=mu, sliding=sliding)
        r = solve(p, "lemke")
        if r.success:
            solved += 1
            v = law_violation(p.W, p.q, p.mu, dim, r.impulse, polygon=dim == 3)
            assert v <= FALSE, (seed, r.message, v)
        else:
            assert r.status in ("numerical_failure", "iteration_limit", "no_solution"), r.message
    assert solved >= 0.95 * cases, (solved, cases)
