"""Oblique inelastic impact (the inelastic contact step of Stewart 2000, worked in Satici's
chapter 11): m = 2 kg, v = (1, -3) m/s, e = 0, mu = 0.2; then sliding under gravity without
lift-off."""

from __future__ import annotations

import numpy as np
from coulomb import HalfSpace, Particle, Point, Scene


def scene(gravity: float) -> Scene:
    s = Scene(dim=2, gravity=(0.0, -gravity))
    p = s.add(Particle(mass=2.0, position=(0.0, 0.0), velocity=(1.0, -3.0)))
    floor = s.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    s.contact(s.attach(p, Point()), floor, mu=0.2, e=0.0)
    return s


def main() -> None:
    tr = scene(0.0).simulate(1e-3, 1e-3)
    pn, pt = tr.contact_impulse[0]
    print(f"P_n   {pn:.6f} N s  (analytic 6)")
    print(f"P_t   {pt:+.6f} N s  (analytic -1.2)")
    print(f"v_t^+ {tr.v[-1, 0]:.6f} m/s (analytic 0.4)")
    print(f"v_n^+ {tr.v[-1, 1]:.6f} m/s (analytic 0)")
    print(f"T     {tr.kinetic_energy[0]:.4f} J -> {tr.kinetic_energy[-1]:.4f} J "
          "(analytic 10 -> 0.16)")
    tr = scene(9.81).simulate(0.5, 1e-3)
    print(f"afterwards, under gravity: max |y| {np.max(np.abs(tr.q[:, 1])):.1e} m, "
          f"max |v_n| {np.max(np.abs(tr.v[1:, 1])):.1e} m/s (no lift-off)")
    print(tr.check())


if __name__ == "__main__":
    main()
