"""Newton's cradle with e = 1: what Newton's law gives when the impacts are simultaneous.

The impulse step applies Newton's law to every touching contact at once: with ``w`` the
contacts' normal relative velocities, ``P`` their impulses and ``W`` the Delassus matrix,
``w+ = w- + W P`` and ``0 <= P  ⊥  w+ + e w- >= 0`` (an LCP; Moreau, Glocker). A row of
touching balls struck at one end is one such problem: the contact that closes has
``w- < 0``, the ones between balls at rest have ``w- = 0``. With e = 1 complementarity gives
``P . (w+ + w-) = 0``, so the kinetic energy ``1/2 v M v`` is kept exactly, and momentum
is kept, but the answer is *not* the textbook one-out-one-in: for three equal balls struck at
``v`` it is ``(-v/3, 2v/3, 2v/3)``, every impulse positive. Only a sequential (wave) model of
the impacts sends the last ball off alone. The oracle below solves the LCP by enumerating its
active sets (independently of the solver) and the test compares the stepper's velocities after
the impact with it."""

from __future__ import annotations

import itertools

import coulomb
import numpy as np
import pytest


def _cradle(dim: int, masses: list[float], v: float, r: float) -> coulomb.Scene:
    scene = coulomb.Scene(dim=dim, gravity=(0.0,) * dim)
    shapes = []
    for k, m in enumerate(masses):
        x = 2.0 * r * k
        vx = v if k == 0 else 0.0
        if dim == 2:
            body = coulomb.RigidBody2D(mass=m, inertia=0.4 * m * r * r, position=(x, 0.0),
                                       velocity=(vx, 0.0))
        else:
            body = coulomb.RigidBody3D(mass=m, inertia=(0.4 * m * r * r,) * 3,
                                       position=(x, 0.0, 0.0), velocity=(vx, 0.0, 0.0))
        shapes.append(scene.attach(scene.add(body), coulomb.Sphere(radius=r)))
    for a, b in itertools.pairwise(shapes):
        scene.contact(a, b, e=1.0)
    return scene


def simultaneous_newton(masses: list[float], v: float, e: float) -> np.ndarray:
    """The balls' velocities after the impact by Newton's law applied to all contacts at
    once: the LCP ``w+ = w- + W P, 0 <= P ⊥ w+ + e w- >= 0`` solved by trying every active
    set (contact k between balls k and k + 1, ``w_k = v_{k+1} - v_k``)."""
    n = len(masses)
    minv = 1.0 / np.asarray(masses)
    d = np.zeros((n - 1, n))  # w = d v
    for k in range(n - 1):
        d[k, k], d[k, k + 1] = -1.0, 1.0
    w_matrix = d @ np.diag(minv) @ d.T
    v0 = np.zeros(n)
    v0[0] = v
    q = (1.0 + e) * (d @ v0)  # w+ + e w- = q + W P
    found = []
    for active in itertools.product([False, True], repeat=n - 1):
        idx = np.flatnonzero(active)
        p = np.zeros(n - 1)
        if idx.size:
            p[idx] = np.linalg.solve(w_matrix[np.ix_(idx, idx)], -q[idx])
        y = q + w_matrix @ p
        if np.all(p >= -1e-12) and np.all(y >= -1e-12):
            found.append(v0 + minv * (d.T @ p))
    assert len(found) >= 1
    return found[0]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("masses", [[1.0, 1.0], [1.0, 1.0, 1.0], [1.0] * 4, [1.0] * 5,
                                    [2.0, 1.0, 0.5], [0.5, 1.0, 3.0, 1.0]])
def test_a_struck_row_of_touching_balls_leaves_as_simultaneous_newton_law_predicts(
        dim: int, masses: list[float]) -> None:
    v, r, h = 1.0, 0.05, 1e-3
    tr = _cradle(dim, masses, v, r).simulate(t_end=5 * h, h=h)
    assert np.all(tr.success)
    nv = 3 if dim == 2 else 6
    after = tr.v[-1].reshape(len(masses), nv)[:, 0]
    want = simultaneous_newton(masses, v, 1.0)
    assert np.max(np.abs(after - want)) < 1e-9 * v
    m = np.asarray(masses)
    # momentum and energy kept exactly (e = 1, no friction)
    assert abs(m @ after - m[0] * v) < 1e-9 * m[0] * v
    assert abs(0.5 * m @ after**2 - 0.5 * m[0] * v * v) < 1e-9 * m[0] * v * v
    # after the impact the balls separate (nobody passes through anybody)
    assert np.all(np.diff(after) >= -1e-9 * v)


def test_three_equal_balls_are_not_one_out_one_in() -> None:
    tr = _cradle(3, [1.0] * 3, 1.0, 0.05).simulate(t_end=3e-3, h=1e-3)
    after = tr.v[-1].reshape(3, 6)[:, 0]
    np.testing.assert_allclose(after, [-1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0], atol=1e-9)
    # the textbook sequential answer (0, 0, 1) is what two isolated impacts in turn give
    assert abs(after[2] - 1.0) > 0.3


def test_two_balls_exchange_velocities_as_in_an_isolated_impact() -> None:
    # with one contact there is nothing simultaneous: Newton's law is the textbook one
    tr = _cradle(3, [1.0, 1.0], 1.0, 0.05).simulate(t_end=3e-3, h=1e-3)
    np.testing.assert_allclose(tr.v[-1].reshape(2, 6)[:, 0], [0.0, 1.0], atol=1e-12)
