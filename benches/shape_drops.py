"""Every shape kind dropped onto a floor at random orientations: does each run's verdict
(`success`) agree with its own certificate (`Trajectory.check()`)?

    python benches/shape_drops.py [--runs 8] [--t-end 0.6]

Each shape (sphere, box, capsule, cylinder, cone, a 20-point hull, a compound) on one rigid
body of 1 kg falls 0.3 m onto a half-space, and onto a box resting on one, at `--runs`
orientations (half nearly flat, half at random), h = 1 ms, default settings. Printed per
shape and floor: runs whose solves all succeeded, runs that `check()` passes, the deepest
gap of any recorded step, and the first violation `check()` names. Figures only, no
assertion: the findings are in the issue notes.
"""

from __future__ import annotations

import argparse

import coulomb
import numpy as np


def _rotate(quat: np.ndarray, points: np.ndarray) -> np.ndarray:
    w, v = quat[0], quat[1:]
    t = 2.0 * np.cross(v, points)
    return points + w * t + np.cross(v, t)


def _orientation(rng: np.random.Generator, flat: bool) -> tuple[float, ...]:
    axis = rng.normal(size=4)
    axis /= np.linalg.norm(axis)
    quat = np.array([1.0, *(0.02 * axis[1:])]) if flat else axis
    return tuple(quat / np.linalg.norm(quat))


def _shapes() -> dict[str, object]:
    cloud = np.random.default_rng(5).normal(size=(20, 3)) * np.array([0.1, 0.07, 0.04])
    return {
        "sphere": lambda: coulomb.Sphere(radius=0.1),
        "box": lambda: coulomb.Box(half_extents=(0.1, 0.05, 0.03)),
        "capsule": lambda: coulomb.Capsule(a=(-0.1, 0, 0), b=(0.1, 0, 0), radius=0.03),
        "cylinder": lambda: coulomb.Cylinder(half_height=0.05, radius=0.08),
        "cone": lambda: coulomb.Cone(half_height=0.05, radius=0.08),
        "hull": lambda: coulomb.ConvexHull(points=cloud.tolist()),
        "compound": lambda: coulomb.Compound(parts=[
            (coulomb.Sphere(radius=0.05), (-0.08, 0, 0), None),
            (coulomb.Box(half_extents=(0.05, 0.05, 0.05)), (0.08, 0, 0), None)]),
    }


def drop(make, seed: int, floor: str, t_end: float) -> tuple[bool, bool, float, str]:
    rng = np.random.default_rng(seed)
    scene = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -9.81))
    body = scene.add(coulomb.RigidBody3D(mass=1.0, inertia=(2e-3, 3e-3, 4e-3),
                                         position=(0.0, 0.0, 0.3),
                                         orientation=_orientation(rng, seed % 2 == 0)))
    shape = scene.attach(body, make())
    if floor == "half-space":
        scene.contact(shape, scene.add(coulomb.HalfSpace(normal=(0, 0, 1), point=(0, 0, 0))),
                      mu=0.5)
    else:
        base = scene.add(coulomb.RigidBody3D(mass=1.0, position=(0, 0, -0.5)))
        slab = scene.attach(base, coulomb.Box(half_extents=(1.0, 1.0, 0.5)))
        ground = scene.add(coulomb.HalfSpace(normal=(0, 0, 1), point=(0, 0, -1.0)))
        scene.contact(slab, ground, mu=0.5)
        scene.contact(shape, slab, mu=0.5)
    tr = scene.simulate(t_end=t_end, h=1e-3)
    check = tr.check()
    first = check.violations[0] if check.violations else ""
    return bool(tr.success), bool(check.ok), float(np.min(tr.min_gap)), first


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=8)
    ap.add_argument("--t-end", type=float, default=0.6)
    args = ap.parse_args()
    print("| shape | floor | solves succeeded | check() passes | deepest gap (m) "
          "| first violation |")
    print("|---|---|---:|---:|---:|---|")
    for name, make in _shapes().items():
        for floor in ("half-space", "box"):
            runs = [drop(make, s, floor, args.t_end) for s in range(args.runs)]
            first = next((r[3] for r in runs if r[3]), "")
            print(f"| {name} | {floor} | {sum(r[0] for r in runs)}/{len(runs)} | "
                  f"{sum(r[1] for r in runs)}/{len(runs)} | {min(r[2] for r in runs):.2e} | "
                  f"{first} |")


if __name__ == "__main__":
    main()
