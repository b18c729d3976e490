"""A box tossed spinning onto a 15 degree ramp beside a bouncing ball, written as an animation
(needs the ``plot`` extra): ``python examples/tumbling_box.py [OUT.gif|OUT.mp4|OUT.html]``."""

from __future__ import annotations

import sys

from coulomb import Box, HalfSpace, RigidBody2D, Scene, Sphere


def main(out: str = "tumbling_box.gif") -> None:
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    ramp = scene.add(HalfSpace.ramp(15.0))
    box = scene.add(RigidBody2D(mass=1.0, inertia=(0.6**2 + 0.3**2) / 12, position=(-1.0, 1.2),
                                velocity=(1.0, 0.0), angular_velocity=4.0, name="box"))
    ball = scene.add(RigidBody2D(mass=0.5, inertia=0.5 * 0.5 * 0.15**2, position=(0.8, 1.5),
                                 name="ball"))
    scene.contact(scene.attach(box, Box((0.3, 0.15))), ramp, mu=0.6, e=0.2)
    scene.contact(scene.attach(ball, Sphere(0.15)), ramp, mu=0.3, e=0.7)
    tr = scene.simulate(2.5, 1e-3)
    print(tr)
    # a spinning corner can dip a few micrometres below the ramp for one step before its
    # contact takes part (a velocity-level step is linear in the rotation), hence gap_tol
    print(tr.check(gap_tol=1e-5))
    path = tr.animate(out, fps=25, figsize=(6, 4))
    print(f"wrote {path} ({len(tr.t[::40])} frames of 1/25 s)")


if __name__ == "__main__":
    main(*sys.argv[1:2])
