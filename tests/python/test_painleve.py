"""Painleve's rod: the seed's A and b, mode enumeration, and an independent dynamics oracle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from coulomb.errors import InvalidParameterError, NonFiniteError
from coulomb.painleve import PainleveRod
from hypothesis import given, settings
from hypothesis import strategies as st


def test_seed_figures_no_sliding_mode() -> None:
    rod = PainleveRod(m=1.0, l=1.0, J=1.0 / 12.0, mu=2.0)
    theta = math.radians(45.0)
    assert rod.A(theta, -1) == pytest.approx(-0.5, abs=1e-14)
    assert rod.b(theta, 0.0) == pytest.approx(-9.81, abs=1e-14)
    res = rod.analyze(theta, 0.0, slip=-1.0)
    assert res.A == pytest.approx(-0.5, abs=1e-14)
    assert not res.consistent and not res.unique and res.modes == {}
    assert "impulse" in res.message


def _accelerations(rod: PainleveRod, theta: float, n: float, f: float) -> np.ndarray:
    """Newton-Euler from the torque r x f, written independently of coulomb.painleve."""
    r = np.array([-0.5 * rod.l * math.cos(theta), -0.5 * rod.l * math.sin(theta)])
    torque = r[0] * n - r[1] * f
    return np.array([f / rod.m, n / rod.m - rod.g0, torque / rod.inertia])


def _contact_point(rod: PainleveRod, state: np.ndarray) -> np.ndarray:
    x, y, th = state[:3]
    return np.array([x - 0.5 * rod.l * math.cos(th), y - 0.5 * rod.l * math.sin(th)])


def _rk4(rod: PainleveRod, state: np.ndarray, n: float, f: float, dt: float) -> np.ndarray:
    def deriv(s: np.ndarray) -> np.ndarray:
        return np.concatenate([s[3:], _accelerations(rod, s[2], n, f)])

    k1 = deriv(state)
    k2 = deriv(state + 0.5 * dt * k1)
    k3 = deriv(state + 0.5 * dt * k2)
    k4 = deriv(state + dt * k3)
    return state + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    theta=st.floats(0.1, 1.4),
    theta_dot=st.floats(-3.0, 3.0),
    n=st.floats(0.0, 20.0),
    f=st.floats(-20.0, 20.0),
    inertia=st.floats(0.02, 0.5),
)
def test_contact_matrix_matches_finite_differences(
    theta: float, theta_dot: float, n: float, f: float, inertia: float
) -> None:
    rod = PainleveRod(m=1.3, l=0.9, mu=0.7, J=inertia)
    state = np.array([0.2, 0.5, theta, 0.3, -0.1, theta_dot])
    mid = _contact_point(rod, state)

    def second_difference(dt: float) -> np.ndarray:
        plus = _contact_point(rod, _rk4(rod, state, n, f, dt))
        minus = _contact_point(rod, _rk4(rod, state, n, f, -dt))
        return (plus - 2 * mid + minus) / dt**2

    # Richardson: the O(dt^2) error of the second difference cancels, whatever the rod's spin
    fd = (4 * second_difference(5e-4) - second_difference(1e-3)) / 3  # [x_c'', g'']
    model = rod.contact_matrix(theta) @ [n, f] + [rod.b(theta, theta_dot), rod.c(theta, theta_dot)]
    assert model[0] == pytest.approx(fd[1], abs=1e-5 * (1 + abs(fd[1])))
    assert model[1] == pytest.approx(fd[0], abs=1e-5 * (1 + abs(fd[0])))
    # the seed's A is the sliding restriction F = -s mu N of the same matrix
    for s in (-1, 1):
        k = rod.contact_matrix(theta)
        assert rod.A(theta, s) == pytest.approx(k[0, 0] - s * rod.mu * k[0, 1], rel=1e-12)


def test_uniform_rod_critical_mu_is_four_thirds() -> None:
    rod = PainleveRod(m=2.0, l=1.5)  # uniform: J = m l^2 / 12
    thetas = np.linspace(0.01, 1.56, 20001)
    mus = np.array([rod.critical_mu(t) for t in thetas])
    assert mus.min() == pytest.approx(4.0 / 3.0, rel=1e-6)
    best = thetas[mus.argmin()]
    # A vanishes at the critical mu, and is negative just above it
    above = PainleveRod(m=2.0, l=1.5, mu=rod.critical_mu(best) * (1 + 1e-6))
    at = PainleveRod(m=2.0, l=1.5, mu=rod.critical_mu(best))
    assert abs(at.A(best, -1)) < 1e-12
    assert above.A(best, -1) < 0


def test_low_friction_has_one_sliding_mode() -> None:
    rod = PainleveRod(mu=0.5)
    theta = math.radians(45.0)
    res = rod.analyze(theta, 0.0, slip=-1.0)
    assert res.unique and list(res.modes) == ["slide-left"]
    n, f = res.modes["slide-left"]
    assert n > 0 and f == pytest.approx(0.5 * n)
    gdd = rod.contact_matrix(theta)[0] @ [n, f] + rod.b(theta)
    assert abs(gdd) < 1e-12


def test_spinning_rod_with_high_friction_is_not_unique() -> None:
    rod = PainleveRod(mu=2.0)
    theta = math.radians(45.0)
    theta_dot = 6.0  # b = 0.5 sin(45) 36 - 9.81 > 0
    res = rod.analyze(theta, theta_dot, slip=-1.0)
    assert res.b > 0 and res.A < 0
    assert set(res.modes) == {"lift-off", "slide-left"}
    assert not res.unique and res.consistent


def test_resting_contact_can_stick() -> None:
    rod = PainleveRod(mu=2.0)
    theta = math.radians(60.0)
    res = rod.analyze(theta, 0.0, slip=0.0)
    assert "stick" in res.modes
    n, f = res.modes["stick"]
    acc = rod.contact_matrix(theta) @ [n, f] + [rod.b(theta), rod.c(theta)]
    assert np.abs(acc).max() < 1e-12 and n > 0 and abs(f) <= rod.mu * n


def test_bad_input() -> None:
    with pytest.raises(InvalidParameterError):
        PainleveRod(m=0.0)
    with pytest.raises(InvalidParameterError):
        PainleveRod(mu=-1.0)
    with pytest.raises(NonFiniteError):
        PainleveRod(l=float("nan"))
    rod = PainleveRod()
    with pytest.raises(InvalidParameterError):
        rod.analyze(2.0)
    with pytest.raises(InvalidParameterError):
        rod.A(0.5, 0)
