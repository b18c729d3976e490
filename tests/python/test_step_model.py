"""Scenes: input checks before any work, the layout of q and v, spatial and sphere-sphere
scenes, the trajectory's checks, repr and plot."""

from __future__ import annotations

import math

import coulomb
import numpy as np
import pytest
from coulomb import (
    Box,
    HalfSpace,
    Particle,
    Point,
    RigidBody2D,
    RigidBody3D,
    Scene,
    Sphere,
)
from coulomb.errors import InvalidParameterError, NonFiniteError, ShapeError
from coulomb.trajectory import TrajectoryCheckError
from helpers import GIL_RELEASED, count_during


def ball_scene(**kw) -> Scene:
    scene = Scene(dim=2)
    b = scene.add(Particle(mass=1.0, position=(0.0, 0.5), velocity=(0.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(b, Point()), floor, **kw)
    return scene


@pytest.mark.parametrize(
    ("make", "exc"),
    [
        (lambda: Scene(dim=4), InvalidParameterError),
        (lambda: Scene(dim=2, gravity=(0.0, math.nan)), NonFiniteError),
        (lambda: Scene(dim=2).add(Particle(mass=0.0)), InvalidParameterError),
        (lambda: Scene(dim=2).add(Particle(mass=-1.0)), InvalidParameterError),
        (lambda: Scene(dim=2).add(Particle(mass=math.inf)), NonFiniteError),
        (lambda: Scene(dim=2).add(Particle(mass=1.0, position=(0.0, 0.0, 0.0))), ShapeError),
        (lambda: Scene(dim=2).add(Particle(mass=1.0, velocity=(math.nan, 0.0))),
         NonFiniteError),
        (lambda: Scene(dim=3).add(RigidBody2D(mass=1.0)), InvalidParameterError),
        (lambda: Scene(dim=2).add(RigidBody2D(mass=1.0, inertia=0.0)), InvalidParameterError),
        (lambda: Scene(dim=3).add(RigidBody3D(mass=1.0, inertia=(1.0, -1.0, 1.0))),
         InvalidParameterError),
        (lambda: Scene(dim=3).add(RigidBody3D(mass=1.0, orientation=(0, 0, 0, 0))),
         InvalidParameterError),
        (lambda: Scene(dim=2).add(HalfSpace((0.0, 0.0), (0.0, 0.0))), InvalidParameterError),
        (lambda: ball_scene(mu=-0.1), InvalidParameterError),
        (lambda: ball_scene(e=1.5), InvalidParameterError),
        (lambda: ball_scene(e=-0.1), InvalidParameterError),
        (lambda: ball_scene().simulate(1.0, 0.0), InvalidParameterError),
        (lambda: ball_scene().simulate(1.0, -1e-3), InvalidParameterError),
        (lambda: ball_scene().simulate(-1.0, 1e-3), InvalidParameterError),
        (lambda: ball_scene().simulate(1.0, math.nan), NonFiniteError),
        (lambda: ball_scene().simulate(1.0, 1e-3, solver="pgs"), InvalidParameterError),
        (lambda: ball_scene().simulate(1.0, 1e-3, relaxation=2.0), InvalidParameterError),
        (lambda: Scene(dim=2).simulate(1.0, 1e-3), InvalidParameterError),
    ],
)
def test_bad_input_is_refused_before_any_work(make, exc):
    with pytest.raises(exc):
        make()


def test_unregistered_handles_and_bad_pairs():
    scene = Scene(dim=2)
    b = scene.add(Particle(mass=1.0))
    with pytest.raises(InvalidParameterError):
        scene.attach(Particle(mass=1.0), Point())
    s = scene.attach(b, Sphere(0.1))
    with pytest.raises(InvalidParameterError):
        scene.attach(b, s)
    with pytest.raises(InvalidParameterError):
        scene.contact(s, HalfSpace())
    s2 = scene.attach(b, Sphere(0.1))
    with pytest.raises(InvalidParameterError, match="same body"):
        scene.contact(s, s2)


def test_layout_and_body_access():
    scene = Scene(dim=2)
    scene.add(Particle(mass=1.0, position=(1.0, 2.0)))
    scene.add(RigidBody2D(mass=1.0, position=(3.0, 4.0), angle=0.5))
    tr = scene.simulate(0.01, 1e-3)
    assert tr.q.shape == (11, 5) and tr.v.shape == (11, 5)
    assert tr.body(1).q[0].tolist() == [3.0, 4.0, 0.5]
    assert tr.body(0).q[0].tolist() == [1.0, 2.0]


def test_spatial_sphere_drop_and_quaternion_stays_unit():
    scene = Scene(dim=3)
    ball = scene.add(RigidBody3D(mass=1.0, inertia=(0.4, 0.4, 0.4), position=(0, 0, 1.0),
                                 velocity=(1.0, 0.0, 0.0), angular_velocity=(0.3, 2.0, -1.0)))
    floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    scene.contact(scene.attach(ball, Sphere(0.1)), floor, mu=0.3, e=0.5)
    tr = scene.simulate(1.5, 1e-3)
    quat = tr.q[:, 3:7]
    assert np.max(np.abs(np.linalg.norm(quat, axis=1) - 1.0)) < 1e-14
    assert tr.min_gap.min() > -1e-9
    assert tr.check().ok, tr.check().violations


def test_two_spheres_collide_head_on():
    # equal masses, e = 1, frictionless, no gravity: the velocities swap
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    a = scene.add(Particle(mass=1.0, position=(-1.0, 0.0, 0.0), velocity=(2.0, 0.0, 0.0)))
    b = scene.add(Particle(mass=1.0, position=(1.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0)))
    sa, sb = scene.attach(a, Sphere(0.5)), scene.attach(b, Sphere(0.5))
    scene.contact(sa, sb, e=1.0)
    tr = scene.simulate(1.0, 1e-3)
    assert tr.body(0).v[-1] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    assert tr.body(1).v[-1] == pytest.approx([2.0, 0.0, 0.0], abs=1e-12)
    assert tr.kinetic_energy[-1] == pytest.approx(2.0, rel=1e-12)
    assert tr.min_gap.min() > -1e-12
    assert tr.check().ok


def _row_of_balls(declare: str) -> Scene:
    # a Newton's cradle: one ball sent along a row of 6 touching-apart balls (e = 1, no
    # friction, no gravity); the pairs are declared, or found by the broad phase
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    shapes = []
    for k in range(7):
        v = (1.0, 0.0, 0.0) if k == 0 else (0.0, 0.0, 0.0)
        body = scene.add(Particle(mass=1.0, position=(1.05 * k, 0.0, 0.0), velocity=v))
        shapes.append(scene.attach(body, Sphere(0.5)))
    if declare == "all":
        for i in range(7):
            for j in range(i + 1, 7):
                scene.contact(shapes[i], shapes[j], e=1.0)
    else:
        scene.contact_spheres(e=1.0)
    return scene


def test_contact_spheres_finds_the_pairs_itself():
    declared = _row_of_balls("all").simulate(1.0, 1e-3)
    found = _row_of_balls("broad").simulate(1.0, 1e-3)
    assert found.success
    np.testing.assert_allclose(found.q, declared.q, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(found.active, declared.active)
    # the momentum has passed down the row to the last ball
    assert found.body(6).v[-1] == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)
    assert found.kinetic_energy[-1] == pytest.approx(0.5, rel=1e-9)
    # broad-phase ids are D + i B + j (D = 0 declared candidates, B = 7 spheres)
    ids = set(found.contact_id.tolist())
    assert ids and all(i // 7 < i % 7 for i in ids)
    with pytest.raises(InvalidParameterError):
        found_scene = _row_of_balls("broad")
        found_scene.contact_spheres()
    with pytest.raises(InvalidParameterError):
        Scene(dim=3).contact_spheres(mu=-1.0)


def test_check_flags_penetration_and_strict_raises():
    # a block started below the floor is a violation the check must report
    scene = Scene(dim=2)
    b = scene.add(Particle(mass=1.0, position=(0.0, -0.01)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(b, Point()), floor)
    tr = scene.simulate(0.01, 1e-3)
    summary = tr.check()
    assert not summary.ok
    assert any("penetration" in v for v in summary.violations)
    with pytest.raises(TrajectoryCheckError, match="penetration"):
        tr.check(strict=True)


def test_solver_options_pass_through():
    scene = Scene(dim=3)
    cube = scene.add(RigidBody3D(mass=1.0, position=(0, 0, 0.5), velocity=(0.5, 0.0, 0.0)))
    floor = scene.add(HalfSpace((0, 0, 0), (0, 0, 1)))
    scene.contact(scene.attach(cube, Box((0.5, 0.5, 0.5))), floor, mu=0.5)
    a = scene.simulate(0.05, 1e-3, solver="lemke", facets=16)
    b = scene.simulate(0.05, 1e-3, solver="nsgs", max_iter=3, warm_start=False,
                       fallback=False)
    assert a.success
    assert a.check().ok
    # three cold sweeps are not enough for four coupled sliding corners: the status says so
    assert np.all(b.iterations <= 3)
    assert (b.success, b.status) == (False, "solver_failures")
    assert set(b.solver_status) == {"iteration_limit"}
    assert any("contact solves did not succeed" in v for v in b.check().violations)
    # with the Lemke fallback every step is decided
    c = scene.simulate(0.05, 1e-3, solver="nsgs", max_iter=3, warm_start=False)
    assert c.success and c.fallback.all()
    assert c.check().ok
    with pytest.raises(InvalidParameterError):
        scene.simulate(0.05, 1e-3, solver="lemke", facets=3)


def test_repr_is_readable():
    tr = ball_scene(e=0.5).simulate(0.5, 1e-3)
    assert (tr.success, tr.status) == (True, "completed")
    assert tr.message == "500 steps, every contact solve solved"
    text = repr(tr)
    assert text.startswith("Trajectory(500 steps of h = 0.001 s")
    assert "min gap" in text and "energy" in text
    assert len(text.splitlines()) <= 8


def test_plot_draws_three_panels():
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    tr = ball_scene(e=0.5).simulate(0.5, 1e-3)
    fig = tr.plot()
    assert len(fig.axes) == 3


def test_exported_names():
    for name in ("Scene", "Particle", "RigidBody2D", "RigidBody3D", "HalfSpace", "Trajectory"):
        assert hasattr(coulomb, name)


def test_simulate_releases_the_gil():
    from coulomb import _core

    scene = Scene(dim=3)
    cube = scene.add(RigidBody3D(mass=2.0, inertia=(1 / 3, 1 / 3, 1 / 3),
                                 position=(0.0, 0.0, 0.5)))
    floor = scene.add(HalfSpace((0, 0, 0), (0, 0, 1)))
    scene.contact(scene.attach(cube, Box((0.5, 0.5, 0.5))), floor, mu=0.5)
    spec = scene._spec()
    result, count = count_during(lambda: _core.step_simulate(spec, 1e-3, 40_000))
    assert result["stopped"] is None
    # see helpers.count_during: a GIL-holding call lets the main thread count to at most ~600
    assert count > GIL_RELEASED


def test_disk_and_sphere_roll_down_a_ramp_without_slipping():
    # a = g sin(theta) / (1 + J / (m r^2)): 2/3 g sin(theta) for a disk, 5/7 for a ball
    th = math.radians(20.0)
    r = 0.1
    scene = Scene(dim=2)
    disk = scene.add(RigidBody2D(mass=1.0, inertia=0.5 * r * r,
                                 position=(r * math.sin(th), r * math.cos(th))))
    ramp = scene.add(HalfSpace.ramp(20.0))
    scene.contact(scene.attach(disk, coulomb.Disk(r)), ramp, mu=0.5)
    tr = scene.simulate(1.0, 1e-3)
    v = tr.v[:, 0] * math.cos(th) - tr.v[:, 1] * math.sin(th)
    assert np.diff(v) / 1e-3 == pytest.approx(2 / 3 * 9.81 * math.sin(th), rel=1e-10)
    assert tr.check().ok

    scene = Scene(dim=3)
    j = 0.4 * r * r
    ball = scene.add(RigidBody3D(mass=1.0, inertia=(j, j, j),
                                 position=(r * math.sin(th), 0.0, r * math.cos(th))))
    ramp = scene.add(HalfSpace.ramp(20.0, dim=3))
    scene.contact(scene.attach(ball, Sphere(r)), ramp, mu=0.5)
    tr = scene.simulate(1.0, 1e-3)
    v = tr.v[:, 0] * math.cos(th) - tr.v[:, 2] * math.sin(th)
    assert np.diff(v) / 1e-3 == pytest.approx(5 / 7 * 9.81 * math.sin(th), rel=1e-10)
    assert np.max(np.abs(tr.v[:, 1])) < 1e-12
    assert tr.check().ok


def test_free_spinning_body_energy_drift_of_the_explicit_gyroscopic_term():
    # measured: +1.8e-4 relative over 10 s at h = 1e-3 (first order: the explicit
    # gyroscopic term in v_free); a symmetric top conserves it exactly
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    scene.add(RigidBody3D(mass=1.0, inertia=(1.0, 2.0, 3.0), angular_velocity=(1.0, 0.1, 0.1)))
    tr = scene.simulate(10.0, 1e-3)
    drift = tr.kinetic_energy[-1] / tr.kinetic_energy[0] - 1.0
    assert 0.0 <= drift < 3e-4
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    scene.add(RigidBody3D(mass=1.0, inertia=(2.0, 2.0, 2.0), angular_velocity=(1.0, 0.5, 0.1)))
    tr = scene.simulate(10.0, 1e-3)
    assert tr.kinetic_energy[-1] == pytest.approx(tr.kinetic_energy[0], rel=1e-13)


@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_sliding_boxes_decelerate_at_mu_g_and_stop(solver):
    # a planar box on two corners and a cube on four, pushed at 1 m/s along x with mu = 0.3:
    # v(t) = 1 - mu g t until t = 1 / (mu g) = 0.340 s, then rest, no tipping, no lift-off
    mu, g, h = 0.3, 9.81, 1e-3
    scene = Scene(dim=2)
    box = scene.add(RigidBody2D(mass=1.0, inertia=1 / 6, position=(0.0, 0.5),
                                velocity=(1.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(box, Box((0.5, 0.5))), floor, mu=mu)
    scene3 = Scene(dim=3)
    cube = scene3.add(RigidBody3D(mass=1.0, inertia=(1 / 6, 1 / 6, 1 / 6),
                                  position=(0.0, 0.0, 0.5), velocity=(1.0, 0.0, 0.0)))
    floor3 = scene3.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    scene3.contact(scene3.attach(cube, Box((0.5, 0.5, 0.5))), floor3, mu=mu)
    for sc in (scene, scene3):
        tr = sc.simulate(0.6, h, solver=solver)
        assert tr.success, tr.message
        vx = tr.v[:, 0]
        n = int(0.3 / h)
        np.testing.assert_allclose(np.diff(vx[:n]) / h, -mu * g, rtol=1e-9)
        assert np.max(np.abs(tr.v[-100:])) < 1e-11
        height = tr.q[:, 1] if sc is scene else tr.q[:, 2]
        assert np.max(np.abs(height - 0.5)) < 1e-12
        assert tr.check().ok, tr.check().violations
