"""NSGS's sticking-set solve (``sticking=True``, the default of ``coulomb.contact.solve``): when
the sweeps slow down, and once more when the budget is spent, the exact answer on the
contacts' current cases is tried and kept only when it passes the tolerance or halves
``scaled_error``. On planted problems with redundant
contacts (singular W) plain Gauss-Seidel sweeps stall along W's null directions; the default
must solve them, each success checked by the law check written in the tests, and
``sticking=False`` must still give the plain sweeps."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
from contact_gen import MODERATE_MU, generate, law_violation, sticking_gain
from coulomb import contact
from coulomb.errors import ArgumentTypeError, InvalidParameterError


def _solve(p, **kw):
    kw.setdefault("max_iter", 2000)
    return contact.solve(p.W, p.q, p.mu, p.dim, tol=1e-8, **kw)


def test_the_default_solves_planted_problems_that_plain_sweeps_leave_unsolved():
    g = sticking_gain(400)
    # no success of either violates the law (checked by the law check of the tests), and a
    # plain solve that succeeds is not lost by the default
    assert g.false == 0 and g.lost == [], g
    # measured (seeds 0..399): 267 solved by plain sweeps, 283 by the default, 32 of them in
    # fewer sweeps or only by the default (`python contact_gen.py 1000 --sticking`: 647,
    # 710, 124)
    assert g.default >= g.plain + 10, g
    assert g.fewer >= 20, g


def test_plain_sweeps_are_the_sweeps_of_the_method_alone():
    # campaign problem 102 (3D, three contacts, mu <= 10, redundant): the sweeps stall, the
    # sticking set of the slowed sweeps is the answer
    p = generate(102, 3, True, mu_choices=MODERATE_MU)
    plain = _solve(p, sticking=False)
    assert plain.status == "iteration_limit" and plain.iterations == 2000
    default = _solve(p)
    assert default.success and default.iterations < 50
    assert law_violation(p.W, p.q, p.mu, 3, default.impulse) <= 1e-9
    # the settings object carries the option, and a batch solves as the single calls do
    via_settings = contact.solve(p.W, p.q, p.mu, 3,
                                 settings=coulomb.NSGSSettings(tol=1e-8, max_iter=2000,
                                                               sticking=False))
    assert np.array_equal(via_settings.impulse, plain.impulse)
    batch = contact.solve_batch([p.W, p.W], [p.q, p.q], [p.mu, p.mu], 3, tol=1e-8,
                                max_iter=2000, sticking=False)
    assert np.array_equal(batch[0].impulse, plain.impulse)
    assert batch[1].status == "iteration_limit"
    batch = contact.solve_batch([p.W], [p.q], [p.mu], 3, tol=1e-8, max_iter=2000)
    assert np.array_equal(batch[0].impulse, default.impulse)


@pytest.mark.parametrize("max_iter", [200, 2000])
def test_a_spent_budget_ends_with_the_sticking_set_of_the_last_iterate(max_iter):
    # generated problem 68 (3D, three contacts, mu <= 10): the sweeps are still 1e-4 away at
    # their budget; the exact answer on the last iterate's cases is the solution
    p = generate(68, 3, True, mu_choices=MODERATE_MU)
    r = _solve(p, max_iter=max_iter)
    assert r.success and r.iterations == max_iter, r.message
    assert r.message.startswith(f"solved in {max_iter} sweeps and the sticking-set solve")
    assert law_violation(p.W, p.q, p.mu, 3, r.impulse) <= 1e-12
    plain = contact.solve(p.W, p.q, p.mu, 3, tol=1e-8, max_iter=max_iter, sticking=False)
    assert not plain.success and "sticking-set" not in plain.message


@pytest.mark.parametrize("method", ["lemke", "prox"])
def test_sticking_off_is_refused_by_the_methods_without_sweeps(method):
    with pytest.raises(InvalidParameterError, match="sticking does not apply"):
        contact.solve(np.eye(2) / 2, [-3.0, 1.0], 0.2, dim=2, method=method, sticking=False)
    with pytest.raises(InvalidParameterError, match="sticking does not apply"):
        contact.solve_batch([np.eye(2) / 2], [[-3.0, 1.0]], 0.2, dim=2, method=method,
                            sticking=False)


@pytest.mark.parametrize("value", [0, 1, "yes", None, np.float64(1.0)])
def test_sticking_must_be_a_bool(value):
    with pytest.raises(ArgumentTypeError, match="sticking"):
        contact.solve(np.eye(2) / 2, [-3.0, 1.0], 0.2, dim=2, sticking=value)
    with pytest.raises(ArgumentTypeError, match="sticking"):
        coulomb.NSGSSettings(sticking=value)


def test_the_stepper_refuses_plain_sweeps():
    with pytest.raises(InvalidParameterError, match="sticking"):
        coulomb.StepSettings(solver=coulomb.NSGSSettings(sticking=False))
    # the default passes through to the stepper's keywords without a conflict
    coulomb.StepSettings(solver=coulomb.NSGSSettings(sticking=True))
