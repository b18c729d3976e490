"""User-defined models in generalized coordinates (a Python loop around the Rust contact
solver) agree with the built-in bodies on the seed's scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from coulomb import GapContact, HalfSpace, Model, Particle, Point, Scene
from coulomb.errors import InvalidParameterError

G = 9.81
TH = math.radians(45.0)


def rod_model(analytic: bool) -> Model:
    # q = (x, y, theta): the seed's rod, lower end at (x - cos(theta) / 2, y - sin(theta) / 2)
    def gap(q):
        return q[1] - 0.5 * math.sin(q[2])

    def jn(q):
        return [0.0, 1.0, -0.5 * math.cos(q[2])]

    def jt(q):
        return [[1.0, 0.0, 0.5 * math.sin(q[2])]]

    def s(q):
        return [q[0] - 0.5 * math.cos(q[2])]

    contact = (GapContact(gap, jn, jt, mu=2.0) if analytic
               else GapContact(gap, tangent_position=s, mu=2.0))
    return Model(dim=2, mass_matrix=np.diag([1.0, 1.0, 1 / 12]),
                 q0=[0.0, 0.5 * math.sin(TH), TH], v0=[-1.0, 0.0, 0.0],
                 force=lambda q, v, t: [0.0, -G, 0.0], contacts=[contact],
                 potential=lambda q: G * q[1])


def rod_scene() -> Scene:
    from coulomb import RigidBody2D, Segment

    scene = Scene(dim=2)
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.0, 0.5 * math.sin(TH)),
                                angle=TH, velocity=(-1.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    return scene


@pytest.mark.parametrize("analytic", [True, False])
def test_painleve_rod_as_a_generalized_model_matches_the_built_in_body(analytic):
    a = rod_model(analytic).simulate(0.1, 1e-3)
    b = rod_scene().simulate(0.1, 1e-3)
    tol = 1e-10 if analytic else 1e-6
    assert np.max(np.abs(a.q - b.q)) < tol
    assert np.max(np.abs(a.v - b.v)) < 10 * tol
    first = a.contact_step == 0
    assert abs(a.contact_velocity[first][0, 1]) < 1e-8  # jams in one step
    assert a.check().ok, a.check().violations
    np.testing.assert_allclose(a.total_energy, b.total_energy, atol=10 * tol)


def test_floor_impact_generalized():
    model = Model(dim=2, mass_matrix=[[0.5, 0.0], [0.0, 0.5]], q0=[0.0, 0.001],
                  v0=[0.0, -3.0],
                  contacts=[GapContact(lambda q: q[1], lambda q: [0.0, 1.0],
                                       lambda q: [[1.0, 0.0]], e=0.6)])
    tr = model.simulate(0.004, 1e-3)
    assert tr.v[-1, 1] == pytest.approx(1.8, abs=1e-12)
    assert tr.contact_impulse[:, 0].sum() == pytest.approx(2.4, abs=1e-12)
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    p = scene.add(Particle(mass=0.5, position=(0.0, 0.001), velocity=(0.0, -3.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(p, Point()), floor, e=0.6)
    np.testing.assert_allclose(tr.q, scene.simulate(0.004, 1e-3).q, atol=1e-15)


def test_generalized_input_checks():
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=[[1.0, 0.0], [0.0, -1.0]], q0=[0.0, 0.0])
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.0],
              contacts=[GapContact(lambda q: q[1], mu=0.5)])
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.0],
              contacts=[GapContact(lambda q: q[1], e=2.0)])
