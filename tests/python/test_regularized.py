"""The tanh-regularized ramp: it creeps where Coulomb sticks, and stiffens as eps -> 0."""

from __future__ import annotations

import math

import numpy as np
import pytest
from coulomb.errors import InvalidParameterError, NonFiniteError
from coulomb.regularized import coulomb_ramp, creep_velocity, simulate_ramp

THETA = math.radians(20.0)


def test_exact_ramp_matches_the_seed() -> None:
    a = 9.81 * (0.4 * math.cos(THETA) - math.sin(THETA))
    assert a == pytest.approx(0.3321, abs=5e-5)
    s, v = coulomb_ramp(THETA, 0.4, 1.0, np.array([3.011, 10.0]))
    assert v[1] == 0.0 and s[1] == pytest.approx(1.505, abs=1e-3)
    assert s[0] == pytest.approx(s[1], abs=1e-6)
    # mu = 0.3 cannot hold the block: it accelerates for ever
    _, v = coulomb_ramp(THETA, 0.3, 1.0, np.array([10.0]))
    assert v[0] > 1.0


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_regularized_block_creeps_at_the_predicted_speed(eps: float) -> None:
    res = simulate_ramp(THETA, 0.4, 1.0, 10.0, eps)
    assert res.success
    v_star = creep_velocity(THETA, 0.4, eps)
    assert v_star == pytest.approx(eps * math.atanh(math.tan(THETA) / 0.4))
    assert res.v[-1] == pytest.approx(v_star, rel=1e-6)
    # the block never stops: after the exact stop time it keeps moving at v*
    s_exact, _ = coulomb_ramp(THETA, 0.4, 1.0, res.t)
    creep = res.s[-1] - s_exact[-1]
    assert creep == pytest.approx(v_star * (10.0 - 3.011), rel=0.05)
    assert np.all(np.diff(res.s) > 0)


def test_cost_of_small_eps_explicit_against_stiff() -> None:
    cost = {}
    for method in ("RK45", "Radau"):
        for eps in (1e-2, 1e-4):
            cost[method, eps] = simulate_ramp(THETA, 0.4, 1.0, 10.0, eps, method=method).nfev
    # an explicit method pays for the stiffness ~ 1/eps; the stiff one does not
    assert cost["RK45", 1e-4] > 30 * cost["RK45", 1e-2]
    assert cost["Radau", 1e-4] < 2 * cost["Radau", 1e-2]


def test_steep_ramp_has_no_creep_velocity() -> None:
    assert math.isnan(creep_velocity(THETA, 0.3, 1e-3))


def test_bad_input() -> None:
    with pytest.raises(InvalidParameterError):
        simulate_ramp(THETA, 0.4, 1.0, 10.0, 0.0)
    with pytest.raises(InvalidParameterError):
        simulate_ramp(THETA, 0.4, 1.0, 10.0, 1e-3, method="Euler")
    with pytest.raises(NonFiniteError):
        simulate_ramp(THETA, float("inf"), 1.0, 10.0, 1e-3)
    with pytest.raises(InvalidParameterError):
        creep_velocity(THETA, -0.1, 1e-3)
