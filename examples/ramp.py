"""Block on a ramp (Satici's chapter 11, "stopping and sticking"): theta = 20 deg, mu = 0.4,
v0 = 1 m/s downhill. Prints the deceleration, stop time and distance against the analytic
figures, and the motion after the stop."""

from __future__ import annotations

import math

import numpy as np
from coulomb import HalfSpace, Particle, Point, Scene


def main(h: float = 1e-3) -> None:
    th = math.radians(20.0)
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    block = scene.add(Particle(mass=1.0, position=(0.0, 0.0),
                               velocity=(math.cos(th), -math.sin(th))))
    ramp = scene.add(HalfSpace.ramp(20.0))
    scene.contact(scene.attach(block, Point()), ramp, mu=0.4)
    tr = scene.simulate(10.0, h)
    s = tr.q[:, 0] * math.cos(th) - tr.q[:, 1] * math.sin(th)
    v = tr.v[:, 0] * math.cos(th) - tr.v[:, 1] * math.sin(th)
    k = int(np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))[0])
    creep = float(np.max(np.hypot(*(tr.q[k:] - tr.q[k]).T)))
    print(f"h = {h:g} s")
    print(f"deceleration   {(v[1] - v[0]) / h:+.4f} m/s^2   (analytic -0.3321)")
    print(f"stop time      {tr.t[k]:.4f} s        (analytic 3.011, within h)")
    print(f"stop distance  {s[k]:.4f} m        (analytic 1.505, within O(h))")
    print(f"motion after the stop through t = 10 s: {creep:.1e} m (analytic: none)")
    print(tr.check())


if __name__ == "__main__":
    main()
