"""Each step's contact problem is solved island by island (groups of contacts no moving body
links), the islands on ``threads`` threads: the trajectory must be the same bitwise on any
number of threads, and a bad count is refused before any step."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
from coulomb import HalfSpace, RigidBody3D, Scene, Sphere

RADIUS = 0.05


def bins(groups: int, side: int) -> Scene:
    """``groups`` bins 3 m apart on one floor, each with a ``side x side`` layer of spheres
    thrown at each other (islands merge and split as they collide)."""
    scene = Scene(dim=3, gravity=(0.0, 0.0, -9.81))
    floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    rng = np.random.default_rng(3)
    spacing = 2.2 * RADIUS
    half = side * spacing / 2 + RADIUS
    inertia = 0.4 * 0.1 * RADIUS**2
    for g in range(groups):
        cx = 3.0 * g
        walls = [floor] + [
            scene.add(HalfSpace(p, n)) for p, n in (
                ((cx - half, 0.0, 0.0), (1.0, 0.0, 0.0)), ((cx + half, 0.0, 0.0), (-1.0, 0.0, 0.0)),
                ((cx, -half, 0.0), (0.0, 1.0, 0.0)), ((cx, half, 0.0), (0.0, -1.0, 0.0)))]
        for i in range(side):
            for j in range(side):
                pos = (cx - half + RADIUS + spacing * (i + 0.5),
                       -half + RADIUS + spacing * (j + 0.5), RADIUS)
                v = (*rng.uniform(-0.5, 0.5, 2), 0.0)
                body = scene.add(RigidBody3D(mass=0.1, inertia=(inertia,) * 3, position=pos,
                                             velocity=v))
                shape = scene.attach(body, Sphere(RADIUS))
                for w in walls:
                    scene.contact(shape, w, mu=0.5)
    scene.contact_spheres(mu=0.5)
    return scene


def test_the_trajectory_is_the_same_on_any_number_of_threads():
    scene = bins(8, 8)
    one = scene.simulate(0.06, 1e-3, threads=1)
    # the islands are solved in parallel from 400 contacts in a step
    assert one.active.max() >= 400
    assert one.success
    for threads in (2, 3, None):
        other = scene.simulate(0.06, 1e-3, threads=threads)
        np.testing.assert_array_equal(other.q, one.q)
        np.testing.assert_array_equal(other.v, one.v)
        np.testing.assert_array_equal(other.iterations, one.iterations)
        np.testing.assert_array_equal(other.solver_error, one.solver_error)


@pytest.mark.parametrize("bad", [0, 1025, -1, 2.5, "2", True])
def test_a_bad_thread_count_is_refused(bad):
    scene = bins(1, 2)
    with pytest.raises((coulomb.errors.InvalidParameterError, TypeError)):
        scene.simulate(0.01, 1e-3, threads=bad)
