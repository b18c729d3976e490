"""A chain of 20 links (rods of 5 cm, hinged end to end by revolute joints) dropped on the
floor, tilted, its lowest end 0.3 m up.

Before anything touches, uniform gravity pulls every link alike, so the joints carry no force
and the chain falls as one rigid piece: its centre of mass follows ``z0 - g t^2 / 2`` (the
step's exact discrete value ``z0 - g t (t + h) / 2``) and the lowest end touches at
``t1 = sqrt(2 (z_low - r) / g)``. Then the chain folds onto the floor (friction 0.3, e = 0)
and comes to rest lying flat: every link's centre at the rod's radius, no kinetic energy.
Prints these figures against the analytic ones, and the joints' largest gap.

Measured (h = 1 ms, 1.5 s): the free fall matches the step's discrete value to 5e-16 m, the
first contact falls in the step of the analytic instant, the joints stay closed to 1.3e-13 m,
the links end within 9e-10 m of lying flat (before the step checked its contact search and
joint remainders on its own velocity, a link ended 1.7e-4 m into the floor) and the kinetic
energy at the end is 1e-31 J. ``success`` is True: every step is solved to its tolerance
1e-12 (it was False while the joints kept rounding-sized targets at rest, which made the
resting chain's sticking contacts inconsistent with its joints at that level, and NSGS
stopped at its sweep limit on some steps at 1.3 to 5 times the tolerance)."""

from __future__ import annotations

import math

import numpy as np
from coulomb import HalfSpace, Revolute, RigidBody2D, Scene, Segment

G = 9.81


def chain(n: int = 20, length: float = 0.05, radius: float = 0.004, tilt: float = 0.4,
          z_low: float = 0.3, mu: float = 0.3) -> Scene:
    scene = Scene(dim=2, gravity=(0.0, -G))
    floor = scene.add(HalfSpace(point=(0.0, 0.0), normal=(0.0, 1.0)))
    c, s = math.cos(tilt), math.sin(tilt)
    m = 0.01
    links = []
    for k in range(n):
        centre = ((k + 0.5) * length * c, z_low + (k + 0.5) * length * s)
        link = scene.add(RigidBody2D(mass=m, inertia=m * length * length / 12.0,
                                     position=centre, angle=tilt))
        rod = scene.attach(link, Segment(a=(-length / 2, 0.0), b=(length / 2, 0.0),
                                         radius=radius))
        scene.contact(rod, floor, mu=mu)
        if links:
            joint = (k * length * c, z_low + k * length * s)
            scene.add(Revolute(link, links[-1], anchor=joint))
        links.append(link)
    return scene


def main(n: int = 20, h: float = 1e-3, t_end: float = 1.5) -> None:
    length, radius, z_low = 0.05, 0.004, 0.3
    tr = chain(n, length, radius, z_low=z_low).simulate(t_end, h)
    x, z, th = tr.q[:, 0::3], tr.q[:, 1::3], tr.q[:, 2::3]
    zc = z.mean(axis=1)
    first = tr.contact_step.min() if tr.contact_step.size else len(tr.t)
    free = slice(0, first + 1)
    t = tr.t[free]
    print(f"{n} links, h = {h:g} s, {t_end} s: success {tr.success}")
    print(f"free fall: centre of mass vs z0 - g t (t + h) / 2: max error "
          f"{np.max(np.abs(zc[free] - (zc[0] - G * t * (t + h) / 2))):.2e} m; "
          f"vs z0 - g t^2 / 2: {np.max(np.abs(zc[free] - (zc[0] - G * t * t / 2))):.2e} m (O(h))")
    t1 = math.sqrt(2 * (z_low - radius) / G)
    print(f"first contact in the step ending at {tr.t[first + 1]:.3f} s, analytic {t1:.4f} s")
    # the joint between link k and k + 1: link k's right end against link k + 1's left end
    half = length / 2
    ends_r = np.stack([x[:, :-1] + half * np.cos(th[:, :-1]),
                       z[:, :-1] + half * np.sin(th[:, :-1])])
    ends_l = np.stack([x[:, 1:] - half * np.cos(th[:, 1:]), z[:, 1:] - half * np.sin(th[:, 1:])])
    gap = np.max(np.linalg.norm(ends_r - ends_l, axis=0))
    print(f"joints: largest gap between hinged ends over the run {gap:.2e} m")
    print(f"at rest: link centres {np.min(z[-1]) - radius:+.2e} .. "
          f"{np.max(z[-1]) - radius:+.2e} m from the rod's radius above the floor (flat: 0), "
          f"|sin(angle)| up to {np.max(np.abs(np.sin(th[-1]))):.2e}, "
          f"kinetic energy {tr.kinetic_energy[-1]:.2e} J")


if __name__ == "__main__":
    main()
