"""A slider-crank without gravity: a crank (r = 0.1 m) hinged to the world, a connecting rod
(l = 0.4 m) hinged to the crank's tip and to a slider on a prismatic joint along x. Started
by spinning the crank, the mechanism has one degree of freedom: the slider's position must be
x(phi) = r cos(phi) + sqrt(l^2 - r^2 sin(phi)^2) for the crank angle phi, and the kinetic
energy stays within the integrator's O(h). Prints both against these values."""

from __future__ import annotations

import math

import numpy as np
from coulomb import Prismatic, Revolute, RigidBody2D, Scene


def main(h: float = 1e-4, t_end: float = 2.0, spin: float = 20.0) -> None:
    r, l = 0.1, 0.4
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    # the crank along +x (angle 0), its centre at r/2; the rod from (r, 0) to (r + l, 0)
    # at this dead centre the slider is at rest and the rod turns about its slider end
    crank = scene.add(RigidBody2D(mass=0.5, inertia=0.5 * r * r / 12, position=(r / 2, 0.0),
                                  velocity=(0.0, spin * r / 2), angular_velocity=spin))
    rod = scene.add(RigidBody2D(mass=1.0, inertia=l * l / 12, position=(r + l / 2, 0.0),
                                velocity=(0.0, spin * r / 2), angular_velocity=-spin * r / l))
    slider = scene.add(RigidBody2D(mass=2.0, inertia=0.01, position=(r + l, 0.0)))
    scene.add(Revolute(crank, None, anchor=(0.0, 0.0)))
    scene.add(Revolute(rod, crank, anchor=(r, 0.0)))
    scene.add(Revolute(slider, rod, anchor=(r + l, 0.0)))
    scene.add(Prismatic(slider, None, anchor=(r + l, 0.0), axis=(1.0, 0.0)))
    tr = scene.simulate(t_end, h)
    phi = tr.q[:, 2]
    x = tr.q[:, 6]
    exact = r * np.cos(phi) + np.sqrt(l * l - (r * np.sin(phi)) ** 2)
    print(f"h = {h:g} s, {t_end} s, crank turns {phi[-1] / (2 * math.pi):.2f} times")
    print(f"slider position vs r cos(phi) + sqrt(l^2 - r^2 sin(phi)^2): "
          f"max error {np.max(np.abs(x - exact)):.2e} m")
    print(f"slider off its axis: max |y| {np.max(np.abs(tr.q[:, 7])):.2e} m, "
          f"max |theta| {np.max(np.abs(tr.q[:, 8])):.2e} rad")
    ke = tr.kinetic_energy
    print(f"kinetic energy {ke[0]:.6f} J, max relative change {np.max(np.abs(ke / ke[0] - 1)):.2e}"
          f" (O(h))")
    print(tr.check())


if __name__ == "__main__":
    main()
