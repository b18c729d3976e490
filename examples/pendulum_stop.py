"""A pendulum released at 1 rad strikes a stop at the vertical with restitution e: each
strike sends it back at -e times its approach rate, so its swing peaks follow
1 - cos(th_n) = e^2 (1 - cos(th_{n-1})). Prints the measured rebound ratios and peaks
against these values."""

from __future__ import annotations

import math

import numpy as np
from coulomb import Revolute, RigidBody2D, Scene


def main(e: float = 0.7, h: float = 1e-4, th0: float = 1.0) -> None:
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    bob = scene.add(RigidBody2D(mass=1.0, inertia=0.01, angle=th0,
                                position=(math.sin(th0), -math.cos(th0))))
    scene.add(Revolute(bob, None, anchor=(0.0, 0.0), limits=(0.0, math.pi / 2), e=e))
    tr = scene.simulate(4.0, h)
    th, w = tr.q[:, 2], tr.v[:, 2]
    print(f"e = {e}, h = {h:g} s: each rebound should be -e times the approach")
    strikes = np.flatnonzero((th[1:-1] <= 1e-9) & (th[:-2] > 1e-9)) + 1
    for i, k in enumerate(strikes[:5]):
        print(f"strike {i + 1}: t = {tr.t[k]:.4f} s, approach {w[k - 1]:+.6f} rad/s, "
              f"rebound {w[k + 1]:+.6f} rad/s, ratio {w[k + 1] / w[k - 1]:+.9f}")
    peaks = np.flatnonzero((th[1:-1] > th[:-2]) & (th[1:-1] >= th[2:]) & (th[1:-1] > 1e-6)) + 1
    expected = th0
    for i, k in enumerate(peaks[:4]):
        expected = math.acos(1.0 - e * e * (1.0 - math.cos(expected)))
        print(f"peak {i + 1}: {th[k]:.6f} rad, analytic {expected:.6f} rad")
    print(tr.check())


if __name__ == "__main__":
    main()
