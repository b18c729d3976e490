"""Boxes on a ramp made of a triangle mesh (a 6 x 6 grid of squares, 72 triangles, tilted by
20 degrees): with mu = 0.2 < tan 20 deg a box slides down at g (sin a - mu cos a), crossing
the triangles' edges without a bump; with mu = 0.5 > tan 20 deg a box sticks where it stands.
Prints the measured acceleration against the analytic one and the sticking box's drift."""

from __future__ import annotations

import math

import numpy as np
from coulomb import Box, RigidBody3D, Scene, TriangleMesh


def ramp_mesh(angle: float, n: int = 6, side: float = 6.0) -> TriangleMesh:
    """an n x n grid of squares over [-side/2, side/2]^2, tilted about y by ``angle`` (the
    surface falling towards +x), each square two triangles wound counter-clockwise from above."""
    s, c = math.sin(angle), math.cos(angle)
    xs = np.linspace(-side / 2, side / 2, n + 1)
    verts = [(x * c, y, -x * s) for x in xs for y in xs]
    tris = []
    for i in range(n):
        for j in range(n):
            a, b = i * (n + 1) + j, (i + 1) * (n + 1) + j
            tris += [(a, b, b + 1), (a, b + 1, a + 1)]
    return TriangleMesh(vertices=verts, triangles=tris)


def main(angle_deg: float = 20.0, h: float = 1e-3, t_end: float = 1.0) -> None:
    a = math.radians(angle_deg)
    scene = Scene(dim=3)
    ramp = scene.add(ramp_mesh(a))
    half = (0.1, 0.1, 0.05)
    # the box's frame turned like the ramp (about y by the ramp's angle)
    quat = (math.cos(a / 2), 0.0, math.sin(a / 2), 0.0)
    normal = np.array([math.sin(a), 0.0, math.cos(a)])
    for k, mu in enumerate((0.2, 0.5)):
        on_surface = np.array([-1.5, -1.0 + 2.0 * k, 1.5 * math.tan(a)])
        body = scene.add(RigidBody3D(mass=1.0, inertia=(0.004, 0.004, 0.007),
                                     position=tuple(on_surface + half[2] * normal),
                                     orientation=quat))
        scene.contact(scene.attach(body, Box(half_extents=half)), ramp, mu=mu)
    tr = scene.simulate(t_end, h)
    g = 9.81
    sliding = tr.body(0)
    x = sliding.q[:, :3] - sliding.q[0, :3]
    dist = x @ np.array([math.cos(a), 0.0, -math.sin(a)])
    want = g * (math.sin(a) - 0.2 * math.cos(a))
    # the step's positions: x_N = a h^2 N (N + 1) / 2 = a t (t + h) / 2
    got = 2.0 * dist[-1] / (tr.t[-1] * (tr.t[-1] + h))
    print(f"ramp {angle_deg} deg of {len(ramp.triangles)} triangles, h = {h:g} s")
    print(f"sliding box (mu 0.2): acceleration {got:.9f} m/s^2, analytic {want:.9f}, "
          f"relative error {abs(got - want) / want:.1e}")
    lift = np.max(np.abs(x @ normal))
    print(f"  its distance from the ramp's plane stays within {lift:.1e} m")
    sticking = tr.body(1)
    drift = np.max(np.abs(sticking.q - sticking.q[0]))
    print(f"sticking box (mu 0.5 > tan {angle_deg} = {math.tan(a):.3f}): drift {drift:.1e}")
    print(tr.check())


if __name__ == "__main__":
    main()
