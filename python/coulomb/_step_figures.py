"""The chapter's figures (Stewart 2000, as taught in Satici ch. 11) reproduced by the impulse
time stepper, as rows for ``coulomb validate``:
``(case, quantity, expected, computed, tolerance)``."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from .model import HalfSpace, Particle, Point, RigidBody2D, Scene, Segment

G = 9.81

FigureRow = tuple[str, str, float, float, float]


def _point(position, velocity, mu=0.0, e=0.0, mass=1.0, gravity=(0.0, -G),
           floor: HalfSpace | None = None) -> Scene:
    scene = Scene(dim=2, gravity=gravity)
    body = scene.add(Particle(mass=mass, position=position, velocity=velocity))
    plane = scene.add(floor or HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(body, Point()), plane, mu=mu, e=e)
    return scene


def rows(h: float = 1e-3) -> Iterator[FigureRow]:
    """Every figure of the stepper's scenes at step size ``h``."""
    th = math.radians(20.0)
    ramp = _point((0.0, 0.0), (math.cos(th), -math.sin(th)), mu=0.4,
                  floor=HalfSpace.ramp(20.0))
    tr = ramp.simulate(10.0, h)
    s = tr.q[:, 0] * math.cos(th) - tr.q[:, 1] * math.sin(th)
    v = tr.v[:, 0] * math.cos(th) - tr.v[:, 1] * math.sin(th)
    k = int(np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))[0])
    case = f"ramp stepped (h = {h:g})"
    yield case, "dv/dt (m/s^2)", -0.3321, float((v[1] - v[0]) / h), 5e-5
    yield case, "t_stop (s)", 3.011, float(tr.t[k]), h + 1e-3
    yield case, "s_stop (m)", 1.505, float(s[k]), h + 1e-3
    yield case, "motion after stop (m)", 0.0, float(np.max(np.abs(tr.q[k:] - tr.q[k]))), 1e-9

    case = f"floor impact stepped (h = {h:g}, impact mid-step)"
    tr = _point((0.0, 0.4 * 3.0 * h), (0.0, -3.0), e=0.6, mass=0.5,
                gravity=(0.0, 0.0)).simulate(4 * h, h)
    yield case, "v_n^+ (m/s)", 1.8, float(tr.v[-1, 1]), 1e-12
    yield case, "P_n (N s)", 2.4, float(tr.contact_impulse[:, 0].sum()), 1e-12
    yield case, "loss (J)", 1.44, float(tr.kinetic_energy[0] - tr.kinetic_energy[-1]), 1e-12

    case = f"oblique inelastic impact stepped (h = {h:g})"
    tr = _point((0.0, 0.0), (1.0, -3.0), mu=0.2, mass=2.0, gravity=(0.0, 0.0)).simulate(h, h)
    yield case, "v_t^+ (m/s)", 0.4, float(tr.v[-1, 0]), 1e-12
    yield case, "v_n^+ (m/s)", 0.0, float(tr.v[-1, 1]), 1e-12

    case = f"bouncing ball e = 0.8 (h = {h / 10:g})"
    tr = _point((0.0, 1.0), (0.0, 0.0), e=0.8).simulate(2.5, h / 10)
    y = tr.q[:, 1]
    apex = y[np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1]
    yield case, "apex ratio (e^2)", 0.64, float(apex[1] / apex[0]), 1e-3

    case = f"Painleve rod stepped (h = {h:g})"
    t45 = math.radians(45.0)
    scene = Scene(dim=2)
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.0, 0.5 * math.sin(t45)),
                                angle=t45, velocity=(-1.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    tr = scene.simulate(0.05, h)
    first = tr.contact_step == 0
    yield case, "contact slip after one step (m/s)", 0.0, \
        float(tr.contact_velocity[first][0, 1]), 1e-10
    yield case, "largest energy change per step (J)", 0.0, \
        max(0.0, float(np.max(np.diff(tr.total_energy)))), 1e-12
