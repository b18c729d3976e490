"""``Scene.contact_all`` covers half-spaces: every attached shape touches every half-space with
contact_all's mu and e, exactly as if each pair were declared by hand, and a declared pair keeps
its own mu and e."""

from __future__ import annotations

import math

import coulomb
import numpy as np
import pytest
from coulomb import Box, Capsule, HalfSpace, RigidBody2D, RigidBody3D, Scene, Sphere

G = 9.81


def _box_inertia(m: float, half: tuple[float, ...]) -> tuple[float, float, float]:
    a, b, c = (2 * x for x in half)
    return (m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)


def _bin(by_hand: bool, mu: float = 0.4, e: float = 0.3) -> Scene:
    """A box, a ball and a capsule thrown into a corner (floor and two walls, one tilted)."""
    scene = Scene(dim=3, gravity=(0.0, 0.0, -G))
    walls = [
        scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))),
        scene.add(HalfSpace((-0.5, 0.0, 0.0), (1.0, 0.0, 0.0))),
        scene.add(HalfSpace((0.0, 0.4, 0.0), (0.0, -math.cos(0.2), math.sin(0.2)))),
    ]
    half = (0.1, 0.08, 0.06)
    box = scene.add(RigidBody3D(mass=1.0, inertia=_box_inertia(1.0, half),
                                position=(-0.2, 0.0, 0.3), velocity=(-2.0, 1.0, 0.0),
                                angular_velocity=(1.0, 2.0, 0.5)))
    ball = scene.add(RigidBody3D(mass=0.5, inertia=(0.002,) * 3, position=(0.2, 0.1, 0.4),
                                 velocity=(-1.0, 2.0, -1.0)))
    rod = scene.add(RigidBody3D(mass=0.3, inertia=(0.0005, 0.004, 0.004),
                                position=(0.0, -0.2, 0.5), orientation=(0.9, 0.1, 0.3, 0.2),
                                velocity=(-1.0, 1.5, 0.0)))
    shapes = [scene.attach(box, Box(half)), scene.attach(ball, Sphere(0.07)),
              scene.attach(rod, Capsule((-0.15, 0.0, 0.0), (0.15, 0.0, 0.0), 0.03))]
    if by_hand:
        for s in shapes:
            for w in walls:
                scene.contact(s, w, mu=mu, e=e)
    scene.contact_all(mu=mu, e=e)
    return scene


@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
def test_contact_all_against_half_spaces_is_every_pair_declared_by_hand(solver: str) -> None:
    auto = _bin(by_hand=False).simulate(0.6, 1e-3, solver)
    hand = _bin(by_hand=True).simulate(0.6, 1e-3, solver)
    # the bodies do reach the walls: many contacts, and the walls hold them (a landing step
    # may leave an overlap of at most h times the approach speed, below 5 m/s here)
    assert np.max(hand.active) >= 6
    assert np.min(hand.min_gap) > -5.0 * 1e-3
    np.testing.assert_array_equal(auto.q, hand.q)
    np.testing.assert_array_equal(auto.v, hand.v)
    # without half-space pairs the bodies would fall through the floor
    assert np.min(auto.q[:, 2]) > 0.0


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("declared_mu", [None, 0.15])
def test_a_box_slides_at_mu_g_with_the_declared_or_contact_all_mu(
        dim: int, declared_mu: float | None) -> None:
    """A box sent along the floor at 2 m/s decelerates at mu g (mu of contact_all, or of the
    pair declared by hand) and stops at v^2 / (2 mu g), without lift-off or creep after."""
    mu_all, v0, h = 0.5, 2.0, 1e-3
    scene = Scene(dim=dim, gravity=[0.0] * (dim - 1) + [-G])
    floor = scene.add(HalfSpace([0.0] * dim, [0.0] * (dim - 1) + [1.0]))
    if dim == 2:
        half2 = (0.1, 0.05)
        body = scene.add(RigidBody2D(mass=1.0, inertia=(0.2**2 + 0.1**2) / 12,
                                     position=(0.0, 0.05), velocity=(v0, 0.0)))
        box = scene.attach(body, Box(half2))
    else:
        half3 = (0.1, 0.1, 0.05)
        body = scene.add(RigidBody3D(mass=1.0, inertia=_box_inertia(1.0, half3),
                                     position=(0.0, 0.0, 0.05), velocity=(v0, 0.0, 0.0)))
        box = scene.attach(body, Box(half3))
    if declared_mu is not None:
        scene.contact(box, floor, mu=declared_mu)
    scene.contact_all(mu=mu_all)
    mu = mu_all if declared_mu is None else declared_mu
    t_stop = v0 / (mu * G)
    tr = scene.simulate(t_stop + 0.3, h)
    assert tr.success
    x = tr.q[:, 0]
    z = tr.q[:, dim - 1]
    stop = v0 * v0 / (2 * mu * G)
    # the step's exact discrete stopping distance is within h v0 of the continuous one
    assert abs(x[-1] - stop) <= v0 * h
    i = int(np.searchsorted(tr.t, 0.5 * t_stop))
    assert abs(tr.v[i, 0] - (v0 - mu * G * tr.t[i])) <= 1e-9 * v0
    assert np.max(np.abs(z - 0.05)) < 1e-9
    after = tr.t > t_stop + 0.05
    assert np.max(np.abs(x[after] - x[-1])) == 0.0


def test_contact_all_half_space_pairs_follow_the_point_form_of_point_shapes() -> None:
    """A Point (no volume: left out of shape pairs) still lands on the floor under
    contact_all, by Newton's law with contact_all's e."""
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    body = scene.add(coulomb.Particle(mass=1.0, position=(0.0, 0.01), velocity=(0.0, -1.0)))
    scene.attach(body, coulomb.Point())
    scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact_all(e=0.5)
    tr = scene.simulate(0.05, 1e-3)
    assert tr.v[-1, 1] == pytest.approx(0.5, rel=1e-12)
