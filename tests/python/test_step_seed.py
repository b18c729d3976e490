"""The impulse time stepper from Python against the seed's figures (free flight, resting block,
ramp, floor impact, oblique inelastic impact, bouncing ball, resting box, Painleve rod)."""

from __future__ import annotations

import math

import coulomb
import numpy as np
import pytest
from coulomb import HalfSpace, RigidBody2D, RigidBody3D, Scene, Segment

# the scene of one point body against a half-space, shared with the validate rows
from coulomb._step_figures import _point as point_scene

G = 9.81




def test_free_flight_is_the_exact_discrete_parabola():
    h = 1e-3
    tr = point_scene((0.0, 10.0), (2.0, 5.0)).simulate(1.0, h)
    k = np.arange(len(tr.t))
    y = 10.0 + 5.0 * k * h - G * h * h * k * (k + 1) / 2
    assert np.max(np.abs(tr.q[:, 1] - y)) < 1e-11
    assert np.max(np.abs(tr.q[:, 0] - 2.0 * k * h)) < 1e-12
    assert np.all(tr.active == 0)
    # semi-implicit Euler loses exactly m g^2 h^2 / 2 of energy per step
    np.testing.assert_allclose(np.diff(tr.total_energy), -0.5 * G * G * h * h, atol=1e-10)
    assert tr.check().ok


def test_resting_block_stays_put_over_10_s():
    tr = point_scene((0.3, 0.0), (0.0, 0.0), mu=0.5).simulate(10.0, 1e-3)
    assert np.max(np.abs(tr.q - [0.3, 0.0])) < 1e-12
    summary = tr.check(strict=True)
    assert summary.ok and summary.violations == []


def ramp_scene(mu: float) -> Scene:
    th = math.radians(20.0)
    return point_scene((0.0, 0.0), (math.cos(th), -math.sin(th)), mu=mu,
                       floor=HalfSpace.ramp(20.0))


def downhill(x: np.ndarray) -> np.ndarray:
    th = math.radians(20.0)
    return x[..., 0] * math.cos(th) - x[..., 1] * math.sin(th)


def test_ramp_decelerates_at_the_seed_rate():
    tr = ramp_scene(0.4).simulate(1.0, 1e-3)
    a = np.diff(downhill(tr.v)) / 1e-3
    assert np.allclose(a, -0.3321, atol=5e-5)
    assert tr.check().ok


@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_ramp_stops_at_the_seed_time_and_distance_then_sticks(h):
    tr = ramp_scene(0.4).simulate(10.0, h)
    stopped = np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))
    k = stopped[0]
    assert abs(tr.t[k] - 3.011) <= h + 1e-3
    assert abs(downhill(tr.q[k]) - 1.505) <= h + 1e-3
    # no motion at all afterwards, through t = 10 s
    assert np.max(np.abs(tr.q[k:] - tr.q[k])) < 1e-9
    assert tr.check().ok


def test_ramp_stop_distance_is_first_order_in_h():
    th = math.radians(20.0)
    a = G * (math.sin(th) - 0.4 * math.cos(th))
    s_star = 0.5 / -a
    errs = []
    for h in (1e-2, 1e-3):
        tr = ramp_scene(0.4).simulate(4.0, h)
        k = np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))[0]
        errs.append(abs(downhill(tr.q[k]) - s_star))
    assert 5.0 < errs[0] / errs[1] < 20.0


def test_ramp_with_mu_0_3_never_sticks():
    tr = ramp_scene(0.3).simulate(10.0, 1e-3)
    speed = downhill(tr.v)
    assert np.all(np.diff(speed) > 0)
    th = math.radians(20.0)
    assert speed[-1] == pytest.approx(1.0 + 10.0 * G * (math.sin(th) - 0.3 * math.cos(th)),
                                      abs=1e-9)


@pytest.mark.parametrize("speed", [3.0, 0.7, 10.0])
@pytest.mark.parametrize("h", [1e-3, 4e-3])
@pytest.mark.parametrize("frac", [0.0, 0.3, 0.999])
def test_floor_impact_newton_wherever_in_the_step(speed, h, frac):
    m, e = 0.5, 0.6
    tr = point_scene((0.0, frac * speed * h), (0.0, -speed), e=e, mass=m,
                     gravity=(0.0, 0.0)).simulate(4 * h, h)
    assert tr.v[-1, 1] == pytest.approx(e * speed, abs=1e-12 * speed)
    p = tr.contact_impulse[:, 0].sum()
    assert p == pytest.approx(m * (1 + e) * speed, abs=1e-12 * speed)
    loss = tr.kinetic_energy[0] - tr.kinetic_energy[-1]
    assert loss == pytest.approx(0.5 * m * speed**2 * (1 - e * e), rel=1e-12)
    if speed == 3.0:
        assert (tr.v[-1, 1], p, loss) == pytest.approx((1.8, 2.4, 1.44), abs=1e-12)
    assert tr.check(strict=True).ok


def test_oblique_inelastic_impact_then_no_lift_off():
    tr = point_scene((0.0, 0.0), (1.0, -3.0), mu=0.2, mass=2.0,
                     gravity=(0.0, 0.0)).simulate(2e-3, 1e-3)
    assert tr.v[-1] == pytest.approx([0.4, 0.0], abs=1e-12)
    assert tr.contact_impulse.sum(axis=0) == pytest.approx([6.0, -1.2], abs=1e-12)
    assert tr.kinetic_energy[-1] == pytest.approx(0.16, abs=1e-12)
    # under gravity the particle slides on, decelerating at mu g, and never leaves the floor
    tr = point_scene((0.0, 0.0), (1.0, -3.0), mu=0.2, mass=2.0).simulate(0.5, 1e-3)
    assert np.max(np.abs(tr.q[:, 1])) < 1e-12 and np.max(np.abs(tr.v[1:, 1])) < 1e-12
    assert tr.check(strict=True).ok


def apexes(y: np.ndarray) -> np.ndarray:
    k = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    return y[k]


@pytest.mark.parametrize("e", [0.5, 0.8])
def test_bouncing_ball_apexes_fall_by_e_squared(e):
    tr = point_scene((0.0, 1.0), (0.0, 0.0), e=e).simulate(2.5, 1e-4)
    ap = apexes(tr.q[:, 1])
    assert len(ap) >= 3
    ratios = ap[1:4] / ap[:3]
    assert np.allclose(ratios, e * e, atol=3e-3), ratios
    summary = tr.check()
    assert summary.ok, summary.violations


def cube_scene(mu: float = 0.5) -> Scene:
    scene = Scene(dim=3)
    m, a = 2.0, 0.5
    i = m * (2 * a) ** 2 / 6
    cube = scene.add(RigidBody3D(mass=m, inertia=(i, i, i), position=(0.1, -0.2, a)))
    floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    scene.contact(scene.attach(cube, coulomb.Box((a, a, a))), floor, mu=mu)
    return scene


@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_resting_box_four_redundant_corners(solver):
    tr = cube_scene().simulate(2.0, 1e-3, solver=solver)
    assert np.all(tr.active == 4)
    assert np.max(np.abs(tr.q - tr.q[0])) < 1e-12
    assert np.max(np.abs(tr.v)) < 1e-11
    assert tr.check(strict=True).ok


def painleve_scene(h_end: float = 0.05) -> Scene:
    th = math.radians(45.0)
    scene = Scene(dim=2)
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.0, 0.5 * math.sin(th)),
                                angle=th, velocity=(-1.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    return scene


def test_painleve_rod_jams_through_an_impulse():
    jam = []
    for h in (1e-2, 1e-3, 1e-4):
        tr = painleve_scene().simulate(0.05, h)
        summary = tr.check()
        assert summary.ok, summary.violations
        first = tr.contact_step == 0
        assert first.sum() == 1
        # the contact end stops sliding within the first step
        assert abs(tr.contact_velocity[first][0, 1]) < 1e-10
        assert np.all(np.diff(tr.total_energy) <= 1e-12)
        jam.append(tr.contact_impulse[first][0])
    err = [np.max(np.abs(p - [0.375, 0.625])) for p in jam]
    assert err[0] > err[1] > err[2] and err[2] < 1e-3


@pytest.mark.parametrize("h", [1e-2, 1e-4])
def test_painleve_rod_falls_flat_every_step_solved(h):
    tr = painleve_scene().simulate(3.0, h)
    assert tr.success, tr.message
    assert abs(tr.q[-1, 1]) < 1e-7 and abs(tr.q[-1, 2]) < 1e-7
    # without correction the closed contact drifts: a few nm below the floor at most
    assert tr.min_gap.min() > -1e-8
    assert not tr.check(gap_tol=1e-8).violations


def test_drift_corrections_measured_effect():
    # the falling rod (h = 1e-3, 3 s): every gap >= 0 to rounding with each option (without
    # correction the sticking end sank 5.3e-9 m before the contact conditions carried the
    # gap's curvature term); the projection gains no energy. The bouncing ball's rebound (apex
    # ratio e^2) is the same under all three.
    none = painleve_scene().simulate(3.0, 1e-3)
    bias = painleve_scene().simulate(3.0, 1e-3, drift="bias", drift_bias=0.2)
    proj = painleve_scene().simulate(3.0, 1e-3, drift="projection")
    assert none.min_gap.min() > -1e-12
    assert bias.min_gap.min() > -1e-12
    assert proj.min_gap.min() > -1e-12
    assert proj.check(strict=True).ok
    assert np.max(proj.energy_gain()) < 1e-12
    ratios = []
    for drift in ("none", "bias", "projection"):
        tr = point_scene((0.0, 1.0), (0.0, 0.0), e=0.8).simulate(2.5, 1e-4, drift=drift)
        ap = apexes(tr.q[:, 1])
        ratios.append(ap[1:4] / ap[:3])
    np.testing.assert_allclose(ratios[1], ratios[0], rtol=1e-12)
    np.testing.assert_allclose(ratios[2], ratios[0], rtol=1e-12)
    with pytest.raises(coulomb.errors.InvalidParameterError):
        painleve_scene().simulate(0.1, 1e-3, drift="bias", drift_bias=0.0)
    with pytest.raises(coulomb.errors.InvalidParameterError):
        painleve_scene().simulate(0.1, 1e-3, drift="baumgarte")


def test_validation_rows_all_pass():
    from coulomb import _step_figures

    rows = list(_step_figures.rows())
    assert len(rows) == 12
    for case, quantity, expected, computed, tol in rows:
        assert abs(computed - expected) <= tol, (case, quantity, expected, computed)


@pytest.mark.parametrize("frac", [0.0, 0.5])
def test_poisson_restitution(frac):
    # a single frictionless impact: Poisson's law agrees with Newton's (seed)
    h = 1e-3
    tr = point_scene((0.0, frac * 3.0 * h), (0.0, -3.0), e=0.6, mass=0.5,
                     gravity=(0.0, 0.0)).simulate(4 * h, h, restitution="poisson")
    assert tr.v[-1, 1] == pytest.approx(1.8, abs=1e-12)
    assert tr.contact_impulse[:, 0].sum() == pytest.approx(2.4, abs=1e-12)
    # with friction (m = 2, v = (1, -3), mu = 0.2, e = 0.5) friction acts in compression and
    # restitution: P_t = -0.2 (6 + 3), v_t^+ = 0.1 (it was 0.4 with friction off in restitution)
    sc = point_scene((0.0, 0.0), (1.0, -3.0), mu=0.2, e=0.5, mass=2.0, gravity=(0.0, 0.0))
    assert sc.simulate(h, h, restitution="poisson").v[-1] == pytest.approx([0.1, 1.5], abs=1e-12)
    assert sc.simulate(h, h).v[-1] == pytest.approx([0.1, 1.5], abs=1e-12)
    with pytest.raises(coulomb.errors.InvalidParameterError):
        sc.simulate(h, h, restitution="stronge")
