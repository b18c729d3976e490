"""Painleve's rod (Stewart 2000; Satici's chapter 11): m = 1, l = 1, J = 1/12, mu = 2,
theta = 45 deg, the lower end sliding left at 1 m/s. No sliding mode with N >= 0 exists
(A = -0.5, b = -9.81); the impulse step jams the end through a tangential impulse."""

from __future__ import annotations

import math

import numpy as np
from coulomb import HalfSpace, RigidBody2D, Scene, Segment


def main() -> None:
    th = math.radians(45.0)
    m, l, j, mu = 1.0, 1.0, 1.0 / 12.0, 2.0
    a = 1 / m - l**2 / (4 * j) * math.cos(th) * (mu * math.sin(th) - math.cos(th))
    print(f"A = {a:.4f} 1/kg (analytic -0.5), b = {-9.81:.2f} m/s^2 (analytic -9.81)")
    print("jam impulse per step size (limit P_n = 0.375, P_t = 0.625 N s):")
    for h in (1e-2, 1e-3, 1e-4):
        scene = Scene(dim=2, gravity=(0.0, -9.81))
        rod = scene.add(RigidBody2D(mass=m, inertia=j, position=(0.0, 0.5 * l * math.sin(th)),
                                    angle=th, velocity=(-1.0, 0.0)))
        floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
        scene.contact(scene.attach(rod, Segment((-0.5 * l, 0.0), (0.5 * l, 0.0))), floor,
                      mu=mu)
        tr = scene.simulate(0.3, h)
        first = tr.contact_step == 0
        pn, pt = tr.contact_impulse[first][0]
        slip = tr.contact_velocity[first][0, 1]
        gain = float(np.max(np.diff(tr.total_energy)))
        print(f"  h = {h:6.0e}: P_n = {pn:.5f}, P_t = {pt:.5f}, end slip after step 1 "
              f"{slip:.1e} m/s, largest energy change per step {gain:+.1e} J, "
              f"solver statuses {sorted(set(tr.solver_status))}")
    print(tr.check())


if __name__ == "__main__":
    main()
