"""A ball dropped from 1 m on a floor with e = 0.8: successive apex heights fall by e^2."""

from __future__ import annotations

import numpy as np
from coulomb import HalfSpace, Particle, Point, Scene


def main(e: float = 0.8, h: float = 1e-4) -> None:
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    ball = scene.add(Particle(mass=1.0, position=(0.0, 1.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(ball, Point()), floor, e=e)
    tr = scene.simulate(4.0, h)
    y = tr.q[:, 1]
    k = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    print(f"e = {e}, h = {h:g} s; apex ratio should be e^2 = {e * e:.4f}")
    for i in range(1, min(len(k), 6)):
        print(f"apex {i}: t = {tr.t[k[i]]:.4f} s, height {y[k[i]]:.5f} m, "
              f"ratio {y[k[i]] / y[k[i - 1]]:.5f}")
    print(tr.check())


if __name__ == "__main__":
    main()
