"""A cube resting on a plane on four redundant corner contacts (W singular): no drift, no
jitter, with both contact solvers."""

from __future__ import annotations

import numpy as np
from coulomb import Box, HalfSpace, RigidBody3D, Scene


def main() -> None:
    m, a = 2.0, 0.5
    i = m * (2 * a) ** 2 / 6
    for solver in ("nsgs", "lemke"):
        scene = Scene(dim=3, gravity=(0.0, 0.0, -9.81))
        cube = scene.add(RigidBody3D(mass=m, inertia=(i, i, i), position=(0.1, -0.2, a)))
        floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
        scene.contact(scene.attach(cube, Box((a, a, a))), floor, mu=0.5)
        tr = scene.simulate(5.0, 1e-3, solver=solver)
        drift = float(np.max(np.abs(tr.q - tr.q[0])))
        jitter = float(np.max(np.abs(tr.v)))
        print(f"{solver:6s}: active contacts {sorted(set(tr.active.tolist()))}, drift "
              f"{drift:.1e} m, max |v| {jitter:.1e} m/s over 5 s; total normal impulse per "
              f"step {tr.normal_impulse_per_step()[-1]:.6f} N s (m g h = {m * 9.81e-3:.6f})")
        print(tr.check())


if __name__ == "__main__":
    main()
