"""A cam and follower: an eccentric disk cam (radius R = 3 cm, its centre e = 1 cm off the
axis) turning at a steady rate w lifts a flat-faced follower (0.1 kg) that slides on a
vertical prismatic joint, frictionless, under gravity.

While it touches, the follower's face sits on top of the disk: ``y = e sin(w t) + R``, so its
acceleration is ``-e w^2 sin(w t)`` and the cam must push with ``N = m (g - e w^2 sin(w t))``.
The push would have to turn negative (pull) at the top of the stroke once ``w > w_jump =
sqrt(g / e)``; a contact cannot pull, so above that rate the follower leaves the cam. The cam
turns on a hinge with a huge inertia, so its rate stays w. Prints, for rates around w_jump,
the follower's largest lift off the cam, and the jump rate found by bisection against
sqrt(g / e).

Measured (h = 0.1 ms): below w_jump the face stays within 4e-7 m of the disk's top (the
step's O(h) on a contact sliding around a curve), above it the follower flies (7e-5 m at
1.02 w_jump, 1.4e-3 m at 1.1); the bisection on a lift of 1e-6 m finds 31.165 rad/s against
31.321, 0.5 % low."""

from __future__ import annotations

import math

import numpy as np
from coulomb import Box, Prismatic, Revolute, RigidBody2D, Scene, Sphere

G = 9.81
R, ECC, M = 0.03, 0.01, 0.1
FACE = 0.02  # the follower's half height


def cam(w: float) -> Scene:
    scene = Scene(dim=2, gravity=(0.0, -G))
    # the cam's body turns about the origin; the disk's centre at angle 0 is (ECC, 0)
    shaft = scene.add(RigidBody2D(mass=1.0, inertia=1e6, position=(0.0, 0.0),
                                  angular_velocity=w))
    disk = scene.attach(shaft, Sphere(radius=R, center=(ECC, 0.0)))
    scene.add(Revolute(shaft, None, anchor=(0.0, 0.0)))
    # the follower's face on the disk's top at angle 0 (y = R), moving with it at e w
    follower = scene.add(RigidBody2D(mass=M, inertia=M * (0.04**2 + (2 * FACE) ** 2) / 12,
                                     position=(0.0, R + FACE), velocity=(0.0, ECC * w)))
    face = scene.attach(follower, Box(half_extents=(0.02, FACE)))
    scene.add(Prismatic(follower, None, anchor=(0.0, R + FACE), axis=(0.0, 1.0)))
    scene.contact(face, disk)
    return scene


def lift(w: float, h: float, turns: float = 2.0) -> float:
    """the follower's largest height above the disk's top over ``turns`` turns (m)."""
    tr = cam(w).simulate(turns * 2 * math.pi / w, h)
    phi = tr.q[:, 2]
    top = ECC * np.sin(phi) + R
    return float(np.max(tr.q[:, 4] - FACE - top))


def main(h: float = 1e-4, threshold: float = 1e-6) -> None:
    w_jump = math.sqrt(G / ECC)
    print(f"analytic jump rate sqrt(g / e) = {w_jump:.4f} rad/s; h = {h:g} s")
    for ratio in (0.9, 0.98, 1.02, 1.1, 1.3):
        print(f"w = {ratio:.2f} w_jump: largest lift off the cam {lift(ratio * w_jump, h):.3e} m")
    lo, hi = 0.9 * w_jump, 1.1 * w_jump
    for _ in range(10):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if lift(mid, h) > threshold else (mid, hi)
    print(f"jump rate (lift above {threshold:g} m) by bisection: {0.5 * (lo + hi):.4f} rad/s, "
          f"relative error {(0.5 * (lo + hi)) / w_jump - 1:+.2e}")


if __name__ == "__main__":
    main()
