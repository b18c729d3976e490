"""A row of Kapla-like planks (0.8 x 2.4 x 12 cm) standing on end, the first one pushed.

A plank pushed to turn about its front bottom edge at the rate ``w`` (the edge sticking, no
bounce) must lift its centre of mass over the edge: it topples only above ``w_c``, where
``1/2 I_edge w_c^2 = m g (rho - H/2)``, with ``rho = sqrt(H^2 + t^2) / 2`` the distance from the
edge to the centre and ``I_edge = m (H^2 + t^2) / 3``. Below it, it tilts up to
``theta_max = beta - acos((H/2 + I_edge w^2 / (2 m g)) / rho)`` (``beta = atan(t / H)``) and
falls back. Prints one plank's largest tilt at 0.9 w_c against that value and whether it
topples at 1.1 w_c, then a row of ten pushed at 1.5 w_c: the time each plank is struck (the
speed of the wave has no closed form) and how far each has turned at the end.

Measured (h = 1 ms): the largest tilt at 0.9 w_c is 0.03681 rad against 0.03756 (2 % low, the
step's O(h)); at 1.1 w_c the plank topples; the row falls plank after plank, the wave
reaching 1.3 m/s; but 99 of the row's 2000 steps miss their tolerance under NSGS
(``success`` False, printed as measured), and in them planks sink up to 4e-6 m into each
other; under ``solver="lemke"`` 1 step is unsolved and no plank is more than 1.3e-7 m into
another."""

from __future__ import annotations

import math

import numpy as np
from coulomb import Box, HalfSpace, RigidBody3D, Scene

G = 9.81
T, W, H = 0.008, 0.024, 0.12  # thickness (along the row, x), width, height
M = 0.02


def row(n: int, spacing: float, push: float) -> Scene:
    scene = Scene(dim=3, gravity=(0.0, 0.0, -G))
    floor = scene.add(HalfSpace(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0)))
    inertia = (M * (W * W + H * H) / 12, M * (T * T + H * H) / 12, M * (T * T + W * W) / 12)
    for k in range(n):
        # the first plank turns about its front bottom edge (x = T/2, z = 0) at `push` rad/s
        # about +y: its centre, at (-T/2, 0, H/2) from the edge, moves at w x r
        w = push if k == 0 else 0.0
        body = scene.add(RigidBody3D(mass=M, inertia=inertia,
                                     position=(k * spacing, 0.0, H / 2),
                                     velocity=(w * H / 2, 0.0, w * T / 2),
                                     angular_velocity=(0.0, w, 0.0)))
        plank = scene.attach(body, Box(half_extents=(T / 2, W / 2, H / 2)))
        scene.contact(plank, floor, mu=0.6)
    scene.contact_all(mu=0.3)
    return scene


def tilt(q: np.ndarray, k: int) -> np.ndarray:
    """plank k's turn about y (rad) from its quaternion (w, x, y, z)."""
    qw, qy = q[:, 7 * k + 3], q[:, 7 * k + 5]
    return 2.0 * np.arctan2(qy, qw)


def main(n: int = 10, spacing: float = 0.06, h: float = 1e-3) -> None:
    rho = math.hypot(H, T) / 2
    i_edge = M * (H * H + T * T) / 3
    beta = math.atan(T / H)
    w_c = math.sqrt(2 * M * G * (rho - H / 2) / i_edge)
    print(f"critical push w_c = {w_c:.4f} rad/s (tipping angle {beta:.4f} rad)")
    w = 0.9 * w_c
    tr = row(1, spacing, w).simulate(0.3, h)
    want = beta - math.acos((H / 2 + i_edge * w * w / (2 * M * G)) / rho)
    print(f"one plank at 0.9 w_c: largest tilt {np.max(tilt(tr.q, 0)):.6f} rad, analytic "
          f"{want:.6f} rad (O(h)); tilt at the end {tilt(tr.q, 0)[-1]:+.2e} rad")
    tr = row(1, spacing, 1.1 * w_c).simulate(1.0, h)
    print(f"one plank at 1.1 w_c: tilt after 1 s {tilt(tr.q, 0)[-1]:.3f} rad (toppled: pi/2 = "
          f"{math.pi / 2:.3f})")
    tr = row(n, spacing, 1.5 * w_c).simulate(2.0, h)
    unsolved = sum(s.name != "SOLVED" for s in tr.solver_status)
    print(f"{n} planks {spacing * 100:.0f} cm apart, the first pushed at 1.5 w_c: success "
          f"{tr.success} ({unsolved} of {len(tr.solver_status)} steps unsolved), deepest "
          f"contact {np.min(tr.contact_gap):.2e} m")
    struck = []
    for k in range(1, n):
        moved = np.flatnonzero(np.abs(tilt(tr.q, k)) > 1e-3)
        struck.append(tr.t[moved[0]] if moved.size else math.nan)
    print("struck at t = " + ", ".join(f"{s:.3f}" for s in struck) + " s")
    gaps = np.diff([0.0, *struck])
    print(f"time between strikes, last five: {', '.join(f'{g:.3f}' for g in gaps[-5:])} s "
          f"(the wave's speed, {spacing / np.mean(gaps[-5:]):.2f} m/s at the end)")
    print("turn at the end: " + ", ".join(f"{tilt(tr.q, k)[-1]:.2f}" for k in range(n)) + " rad")


if __name__ == "__main__":
    main()
