"""Planar solids: every 2D shape (disk, box, convex polygon, segment, capsule, compound) rests
on a static polyline and on a box without creeping or sinking, a box slides on a polyline at
exactly mu g and stops where the analytic answer says, and bad compounds and polylines are
refused before any step."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from coulomb import (
    Box,
    Capsule,
    Compound,
    Disk,
    HalfSpace,
    Polygon,
    Polyline,
    RigidBody2D,
    Scene,
    Segment,
)
from coulomb.errors import InvalidParameterError, ShapeError

G = 9.81
#: a floor at y = 0 for |x| < 1, rising to 0.5 at |x| = 3.
TERRAIN = [(-3.0, 0.5), (-1.0, 0.0), (1.0, 0.0), (3.0, 0.5)]


def _shapes() -> list[tuple[str, Any, float]]:
    """(name, shape, depth of its lowest point below its body's origin)."""
    return [
        ("disk", Disk(0.1), 0.1),
        ("box", Box((0.2, 0.1)), 0.1),
        ("triangle", Polygon([(-0.2, -0.1), (0.2, -0.1), (0.0, 0.2)]), 0.1),
        ("segment", Segment((-0.2, 0.0), (0.2, 0.0)), 0.0),
        ("rounded segment", Segment((-0.2, 0.0), (0.2, 0.0), radius=0.04), 0.04),
        ("capsule", Capsule((-0.2, 0.0), (0.2, 0.0), 0.05), 0.05),
        ("dumbbell compound", Compound([(Disk(0.05), (-0.2, 0.0), None),
                                        (Disk(0.05), (0.2, 0.0), None),
                                        (Box((0.2, 0.01)), None, None)]), 0.05),
        ("turned L compound", Compound([(Box((0.15, 0.02)), (0.0, -0.04), None),
                                        (Box((0.1, 0.02)), (-0.13, 0.06), 1.5707963267948966)]),
         0.06),
    ]


@pytest.mark.parametrize("k", range(len(_shapes())), ids=[s[0] for s in _shapes()])
def test_every_2d_shape_rests_on_a_polyline_and_on_a_box_without_creep(k: int) -> None:
    name, shape, depth = _shapes()[k]
    scene = Scene(dim=2, gravity=(0.0, -G))
    scene.add(Polyline(TERRAIN))
    # a box resting on the terrain, the shape resting on it, and the same shape on the terrain
    base = scene.add(RigidBody2D(mass=2.0, inertia=0.2, position=(-0.4, 0.1)))
    scene.attach(base, Box((0.3, 0.1)))
    top = scene.add(RigidBody2D(mass=0.5, inertia=0.01, position=(-0.4, 0.2 + depth)))
    scene.attach(top, shape)
    # a segment without radius on the polyline (no thickness on either side) has no
    # defined normal at contact: left out (the Polyline's documentation says so)
    weight = 2.5
    if depth > 0.0:
        alone = scene.add(RigidBody2D(mass=0.5, inertia=0.01, position=(0.5, depth)))
        scene.attach(alone, _shapes()[k][1])
        weight += 0.5
    scene.contact_all(mu=0.6)
    tr = scene.simulate(1.0, 1e-3)
    assert tr.success, name
    drift = np.max(np.abs(tr.q - tr.q[0]))
    assert drift < 1e-9, f"{name}: drift {drift:.2e}"
    # the contacts carry the weights: the floor every body, the box the shape on it
    per_step = tr.normal_impulse_per_step()[-1]
    assert per_step == pytest.approx((weight + 0.5) * G * 1e-3, rel=1e-6)


@pytest.mark.parametrize("mu", [0.2, 0.7])
def test_a_box_slides_on_a_polyline_at_mu_g_and_stops_without_creep(mu: float) -> None:
    v0, h = 1.5, 1e-3
    scene = Scene(dim=2, gravity=(0.0, -G))
    line = scene.add(Polyline(TERRAIN))
    body = scene.add(RigidBody2D(mass=1.0, inertia=(0.2**2 + 0.1**2) / 12,
                                 position=(-0.6, 0.05), velocity=(v0, 0.0)))
    box = scene.attach(body, Box((0.1, 0.05)))
    scene.contact(box, line, mu=mu)
    t_stop = v0 / (mu * G)
    tr = scene.simulate(t_stop + 0.3, h)
    assert tr.success
    x, y = tr.q[:, 0], tr.q[:, 1]
    assert abs((x[-1] - x[0]) - v0 * v0 / (2 * mu * G)) <= v0 * h
    i = int(np.searchsorted(tr.t, 0.5 * t_stop))
    assert abs(tr.v[i, 0] - (v0 - mu * G * tr.t[i])) <= 1e-9 * v0
    assert np.max(np.abs(y - 0.05)) < 1e-9
    # stopped: no creep beyond rounding (MuJoCo's soft contact creeps by 1e-2 m on a ramp)
    after = tr.t > t_stop + 0.05
    assert np.max(np.abs(x[after] - x[-1])) < 1e-12


def test_a_compound_rests_on_another_compound_on_a_half_plane() -> None:
    """A dumbbell (two disks on a bar) dropped 1 cm onto a table (a top on two legs, both
    compounds) standing on a floor comes to rest on its disks on the table's top: its centre
    at the top's height plus a disk's radius, the table unmoved."""
    scene = Scene(dim=2, gravity=(0.0, -G))
    scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    table = Compound([(Box((0.5, 0.02)), (0.0, 0.1), None),
                      (Box((0.02, 0.04)), (-0.4, 0.04), None),
                      (Box((0.02, 0.04)), (0.4, 0.04), None)])
    dumbbell = Compound([(Disk(0.05), (-0.2, 0.0), None), (Disk(0.05), (0.2, 0.0), None),
                         (Box((0.2, 0.01)), None, None)])
    low = scene.add(RigidBody2D(mass=3.0, inertia=0.3, position=(0.0, 0.0)))
    up = scene.add(RigidBody2D(mass=1.0, inertia=0.05, position=(0.05, 0.18)))
    scene.attach(low, table)
    scene.attach(up, dumbbell)
    scene.contact_all(mu=0.5)
    tr = scene.simulate(0.5, 1e-3)
    assert tr.success
    assert np.max(np.abs(tr.q[:, :3] - tr.q[0, :3])) < 1e-9
    assert tr.q[-1, 4] == pytest.approx(0.12 + 0.05, abs=1e-9)
    assert tr.q[-1, 3] == pytest.approx(0.05, abs=1e-12)
    assert np.max(np.abs(tr.v[-1])) < 1e-9


def test_bad_2d_compounds_and_polylines_are_refused() -> None:
    scene = Scene(dim=2)
    body = scene.add(RigidBody2D(mass=1.0, inertia=1.0))
    with pytest.raises(ShapeError):
        scene.attach(body, Compound([]))
    with pytest.raises(InvalidParameterError):
        scene.attach(body, Compound([(Compound([(Disk(1.0), None, None)]), None, None)]))
    with pytest.raises(ShapeError):
        scene.add(Polyline([(0.0, 0.0)]))
    with pytest.raises(InvalidParameterError):
        scene.add(Polyline([(0.0, 0.0), (1.0, 0.0), (1.0, 0.0)]))
    with pytest.raises(InvalidParameterError):
        Scene(dim=3).add(Polyline([(0.0, 0.0), (1.0, 0.0)]))
