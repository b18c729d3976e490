"""Steps per second and the scenes' figures: coulomb's impulse stepper against MuJoCo.

    python benches/peer_step.py [--quick] [--repeats N]

The same scenes, data and step size in both (see benches/mujoco_scenes.py for MuJoCo's side):
a 1 kg box sent down a 20 deg ramp at 1 m/s (mu 0.4; gravity tilted, as in MuJoCo's model), a
0.5 kg ball hitting the floor at 3 m/s (e 0.6 asked), a box resting on the floor, and piles of
100 and 1000 spheres falling into a box (mu 0.5). MuJoCo runs through ``mujoco.rollout`` (its
loop in C++), coulomb through ``Scene.simulate`` (its loop in Rust); each is the best of a
few runs' wall time. Writes the table into BENCHMARKS.md between the step-peers markers.
"""

from __future__ import annotations

import argparse
import datetime
import itertools
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import coulomb
import mujoco_scenes as mj
from coulomb import Box, HalfSpace, Revolute, RigidBody3D, Scene, Sphere
from markers import BENCHMARKS, write_block

ROOT = Path(__file__).resolve().parents[1]
G0 = 9.81


#: timed runs per scene, the best kept (both coulomb's and MuJoCo's; --repeats sets it).
REPEATS = 3


def _best(build, t_end: float, h: float, solver: str, repeats: int | None = None):
    """Builds the scene (not timed, as MuJoCo's model compile is not) and times simulate."""
    best = math.inf
    out = None
    for _ in range(REPEATS if repeats is None else repeats):
        scene = build()
        start = time.perf_counter()
        out = scene.simulate(t_end, h, solver)
        best = min(best, time.perf_counter() - start)
    return out, best


def _box_inertia(m: float, half: tuple[float, float, float]) -> tuple[float, float, float]:
    a, b, c = (2 * x for x in half)
    return (m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)


def _floor() -> HalfSpace:
    return HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))


def coulomb_ramp(h: float, solver: str, t_end: float = 10.0) -> dict:
    th = math.radians(20.0)
    half = (0.05, 0.05, 0.05)

    def run():
        scene = Scene(dim=3, gravity=(G0 * math.sin(th), 0.0, -G0 * math.cos(th)))
        box = scene.add(
            RigidBody3D(
                mass=1.0,
                inertia=_box_inertia(1.0, half),
                position=(0.0, 0.0, 0.05),
                velocity=(1.0, 0.0, 0.0),
            )
        )
        scene.contact(scene.attach(box, Box(half)), scene.add(_floor()), mu=0.4)
        return scene

    tr, sec = _best(run, t_end, h, solver)
    x = tr.q[:, 0]
    i5 = int(np.searchsorted(tr.t, 5.0))
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "distance at 3.011 s (m)": float(np.interp(3.011, tr.t, x)),
            "creep 5 s..10 s (m)": float(x[-1] - x[i5]),
        },
    }


def impact_scene() -> Scene:
    """The floor impact: a 0.5 kg ball of radius 0.1 m 1 cm above the floor at 3 m/s, e = 0.6
    (mujoco_scenes.floor_impact_xml is MuJoCo's)."""
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    ball = scene.add(
        RigidBody3D(
            mass=0.5, inertia=(0.002,) * 3, position=(0.0, 0.0, 0.11), velocity=(0.0, 0.0, -3.0)
        )
    )
    scene.contact(scene.attach(ball, Sphere(0.1)), scene.add(_floor()), e=0.6)
    return scene


def coulomb_impact(h: float, solver: str, t_end: float = 0.2) -> dict:
    tr, sec = _best(impact_scene, t_end, h, solver)
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {"rebound ratio (e asked 0.6)": float(tr.v[-1, 2] / 3.0)},
    }


def coulomb_resting_box(h: float, solver: str, t_end: float = 10.0) -> dict:
    half = (0.1, 0.1, 0.05)

    def run():
        scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
        box = scene.add(
            RigidBody3D(mass=1.0, inertia=_box_inertia(1.0, half), position=(0.0, 0.0, 0.05))
        )
        scene.contact(scene.attach(box, Box(half)), scene.add(_floor()), mu=0.5)
        return scene

    tr, sec = _best(run, t_end, h, solver)
    drift = float(np.max(np.abs(tr.q[:, :2] - tr.q[0, :2])))
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "horizontal drift (m)": drift,
            "penetration (m)": float(max(0.0, -np.min(tr.min_gap))),
        },
    }


def coulomb_pile(count: int, h: float, solver: str, t_end: float = 1.0) -> dict:
    radius = 0.05
    side = math.ceil(count ** (1 / 3))
    spacing = 2.2 * radius
    half = side * spacing / 2 + radius

    def run():
        scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
        walls = [scene.add(_floor())] + [
            scene.add(HalfSpace(p, n))
            for p, n in (
                ((-half, 0.0, 0.0), (1.0, 0.0, 0.0)),
                ((half, 0.0, 0.0), (-1.0, 0.0, 0.0)),
                ((0.0, -half, 0.0), (0.0, 1.0, 0.0)),
                ((0.0, half, 0.0), (0.0, -1.0, 0.0)),
            )
        ]
        shapes = []
        centers = np.array(list(_centers(count, side, spacing, half, radius)))
        for pos in centers:
            inertia = 0.4 * 0.1 * radius * radius
            body = scene.add(RigidBody3D(mass=0.1, inertia=(inertia,) * 3, position=tuple(pos)))
            shapes.append(scene.attach(body, Sphere(radius)))
        for s in shapes:
            for w in walls:
                scene.contact(s, w, mu=0.5)
        # every sphere pair: the stepper's broad phase finds the near ones each step
        scene.contact_spheres(mu=0.5)
        return scene

    tr, sec = _best(run, t_end, h, solver)
    pos = tr.q.reshape(len(tr.t), count, 7)[:, :, :3]
    moved = float(np.max(np.linalg.norm(pos - pos[0], axis=2)))
    solved = int(np.sum(np.isin(tr.solver_status, ["solved", "no_contact"])))
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "contacts per step (mean)": float(np.mean(tr.active)),
            "us per step per contact": 1e6 * sec / max(1, int(np.sum(tr.active))),
            "steps solved": f"{solved}/{len(tr.t) - 1}",
            "largest displacement (m)": moved,
        },
    }


def _centers(count, side, spacing, half, radius):
    for k in range(count):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        yield (
            -half + radius + spacing * (i + 0.5),
            -half + radius + spacing * (j + 0.5),
            radius + 0.01 + spacing * l,
        )


def coulomb_tower(h: float, solver: str, count: int = 10, t_end: float = 10.0,
                  half: float = 0.1, mu: float = 0.5) -> dict:
    """`count` cubes stacked exactly on the floor (as examples/box_tower.py, h = 1 ms)."""

    def run():
        scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
        floor = scene.add(_floor())
        boxes = []
        for k in range(count):
            body = scene.add(
                RigidBody3D(mass=1.0, inertia=_box_inertia(1.0, (half,) * 3),
                            position=(0.0, 0.0, half * (2 * k + 1)))
            )
            boxes.append(scene.attach(body, Box((half, half, half))))
        scene.contact(boxes[0], floor, mu=mu)
        for a, b in itertools.pairwise(boxes):
            scene.contact(b, a, mu=mu)
        return scene

    tr, sec = _best(run, t_end, h, solver)
    pos = tr.q.reshape(len(tr.t), count, 7)
    drift = float(np.max(np.abs(pos[:, :, :3] - pos[0, :, :3])))
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "largest drift (m)": drift,
            "top box sank (m)": float(pos[0, -1, 2] - pos[-1, -1, 2]),
            "penetration (m)": float(max(0.0, -np.min(tr.min_gap))),
            "steps solved": _solved(tr),
        },
    }


def _solved(tr) -> str:
    ok = int(np.sum(np.isin(tr.solver_status, ["solved", "no_contact"])))
    return f"{ok}/{len(tr.t) - 1}"


def coulomb_box_pile(count: int, h: float, solver: str, t_end: float = 1.0,
                     half: float = 0.05, mu: float = 0.5, repeats: int | None = None) -> dict:
    """`count` cubes dropped into a box (floor and four walls; the layout of
    mujoco_scenes.box_pile), every pair by contact_all."""
    _side, wall, centres = mj.box_pile_layout(count, half)
    turn = math.radians(10.0)
    inertia = _box_inertia(0.1, (half,) * 3)

    def run():
        scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
        scene.add(_floor())
        for p, n in (
            ((-wall, 0.0, 0.0), (1.0, 0.0, 0.0)),
            ((wall, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            ((0.0, -wall, 0.0), (0.0, 1.0, 0.0)),
            ((0.0, wall, 0.0), (0.0, -1.0, 0.0)),
        ):
            scene.add(HalfSpace(p, n))
        for k, c in enumerate(centres):
            a = turn * (k % 3)
            body = scene.add(RigidBody3D(
                mass=0.1, inertia=inertia, position=c,
                orientation=(math.cos(a / 2), 0.0, 0.0, math.sin(a / 2))))
            scene.attach(body, Box((half, half, half)))
        # every box pair found by the broad phase, and every box against the five half-spaces
        scene.contact_all(mu=mu)
        return scene

    tr, sec = _best(run, t_end, h, solver, repeats)
    q_end = tr.q[-1].reshape(count, 7)
    v_end = tr.v[-1].reshape(count, 6)
    lowest = float(np.min(mj._lowest_corner(q_end, half)))
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "contacts per step (mean)": float(np.mean(tr.active)),
            "steps solved": _solved(tr),
            "floor penetration at the end (m)": max(0.0, -lowest),
            "penetration, any contact (m)": float(max(0.0, -np.min(tr.min_gap))),
            "largest speed at the end (m/s)": float(np.max(np.linalg.norm(v_end[:, :3], axis=1))),
        },
    }


def coulomb_chain(h: float, solver: str, links: int = 20, t_end: float = 1.0,
                  length: float = 0.05, radius: float = 0.005) -> dict:
    """`links` rods hinged end to end about y by revolute joints, the first to the world at
    the origin, released horizontal (mujoco_scenes.chain: same masses and inertias)."""
    m = 0.01
    inertia = (m * radius * radius / 2, m * (3 * radius**2 + length**2) / 12,
               m * (3 * radius**2 + length**2) / 12)

    def run():
        scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
        prev = None
        for k in range(links):
            body = scene.add(RigidBody3D(mass=m, inertia=inertia,
                                         position=((k + 0.5) * length, 0.0, 0.0)))
            scene.add(Revolute(body, prev, anchor=(k * length, 0.0, 0.0), axis=(0.0, 1.0, 0.0)))
            prev = body
        return scene

    tr, sec = _best(run, t_end, h, solver)
    q = tr.q.reshape(len(tr.t), links, 7)
    ends = [_rotate(q[:, :, 3:], np.array([s * length / 2, 0.0, 0.0])) + q[:, :, :3]
            for s in (-1.0, 1.0)]
    gap = float(np.max(np.linalg.norm(ends[1][:, :-1] - ends[0][:, 1:], axis=2)))
    pivot = float(np.max(np.linalg.norm(ends[0][:, 0], axis=1)))
    energy = tr.kinetic_energy + tr.potential_energy
    return {
        "steps": len(tr.t) - 1,
        "seconds": sec,
        "figures": {
            "joint gap, largest (m)": max(gap, pivot),
            "energy change (J)": float(energy[-1] - energy[0]),
            "tip height at the end (m)": float(ends[1][-1, -1, 2]),
        },
    }


def _rotate(quat: np.ndarray, p: np.ndarray) -> np.ndarray:
    """the body-frame point p turned by unit quaternions (..., 4) = (w, x, y, z)."""
    w = quat[..., :1]
    u = quat[..., 1:]
    t = 2.0 * np.cross(u, p)
    return p + w * t + np.cross(u, t)


#: the box scenes' profile (callgrind instruction counts, not measured by this script).
PROFILE_NOTE = """### Where the box scenes' steps go (callgrind)

`valgrind --tool=callgrind target/release/examples/step_profile tower 10 300` and
`... box-pile 125 130` (the same scenes in Rust, `benches/profile/step_profile.rs`), instructions
before and after the narrow phase kept its manifold, GJK simplex and EPA per pair
(`rust/geometry/convex.rs`; before: parry's dispatcher, which makes a new EPA and, against a
half-space, a new point buffer per query):

| scene | narrow phase before | after | whole run before | after |
|---|---:|---:|---:|---:|
| tower of 10 boxes, 300 steps | 120,550,138 | 103,017,804 | 8,010,469,091 | 8,000,045,563 |
| 125 boxes falling in a box, 130 steps | 24,771,843 | 21,069,940 | 1,780,023,488 | 1,776,195,705 |

A settled step of a box on a box and a capsule on the floor allocates nothing (12 allocations
before; `tests/step_solids_alloc.rs`, `tests/geometry_alloc.rs`). The narrow phase is about 1 %
of the box scenes' instructions: on the tower 78 % go to the robust mode's fallback (faer's
sparse LU alone 46 %) and 20 % to NSGS, which misses its tolerance (1e-12) on 826 of the first
2000 steps (`step_profile tower 10 2000`); after the 125 boxes land, each step is solved by the
fallback too. The box scenes' speed is the contact solver's on these redundant face contacts
(four points per face), not the geometry's. (Those shares are from before the stepper's NSGS
used its sticking-set solve and the faces were clipped as polygons: the tower's 2000 steps now
take 3.9G instructions with no fallback; see "Box faces: the NSGS stall".)"""


def _fmt_fig(figs: dict) -> str:
    out = []
    for k, v in figs.items():
        out.append(f"{k}: {v:.4g}" if isinstance(v, float) else f"{k}: {v}")
    return "; ".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="skip the 1000-sphere pile, 2 s of the tower, 27 boxes for 216 and 1000")
    ap.add_argument("--no-write", action="store_true", help="print only")
    ap.add_argument("--repeats", type=int, default=3,
                    help="timed runs per scene, the best kept (more on a loaded machine)")
    args = ap.parse_args()
    global REPEATS
    REPEATS = mj.REPEATS = max(1, args.repeats)
    h = 1e-3
    rows = []

    def add(scene: str, who: str, res: dict) -> None:
        sps = res["steps"] / res["seconds"]
        rows.append((scene, who, sps, res["seconds"], _fmt_fig(res["figures"])))
        print(
            f"{scene:24s} {who:18s} {sps:12.0f} steps/s  {_fmt_fig(res['figures'])}",
            file=sys.stderr,
        )

    def add_peer(run: mj.PeerRun) -> None:
        add(
            run.scene,
            "MuJoCo (defaults)",
            {"steps": run.steps, "seconds": run.seconds, "figures": run.figures},
        )

    for solver in ("nsgs", "lemke"):
        add("ramp", f"coulomb {solver}", coulomb_ramp(h, solver))
    add_peer(mj.ramp(h))
    for solver in ("nsgs", "lemke"):
        add("floor impact", f"coulomb {solver}", coulomb_impact(h, solver))
    add_peer(mj.floor_impact(h))
    for solver in ("nsgs", "lemke"):
        add("resting box", f"coulomb {solver}", coulomb_resting_box(h, solver))
    add_peer(mj.resting_box(h))
    counts = [100] if args.quick else [100, 1000]
    for count in counts:
        add(f"pile of {count} spheres", "coulomb nsgs", coulomb_pile(count, h, "nsgs"))
        add_peer(mj.sphere_pile(count, h))
    t_tower = 2.0 if args.quick else 10.0
    add("tower of 10 boxes", "coulomb nsgs", coulomb_tower(h, "nsgs", t_end=t_tower))
    add_peer(mj.box_tower(10, h, t_end=t_tower))
    # the box piles once each (the 1000 boxes take about a minute here), 0.5 s: the boxes
    # land at 0.1 s
    piles, t_pile, once = ([27], 0.5, None) if args.quick else ([216, 1000], 0.5, 1)
    for boxes in piles:
        add(f"pile of {boxes} boxes", "coulomb nsgs",
            coulomb_box_pile(boxes, h, "nsgs", t_end=t_pile, repeats=once))
        add_peer(mj.box_pile(boxes, h, t_end=t_pile, repeats=once))
    add("chain of 20 links", "coulomb nsgs", coulomb_chain(h, "nsgs"))
    add_peer(mj.chain(20, h))

    try:
        rev = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT
        ).stdout.strip()
    except OSError:
        rev = "unknown"
    import mujoco

    lines = [
        "## The impulse stepper: coulomb vs MuJoCo",
        "",
        f"Generated by `benches/peer_step.py` on "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC (revision {rev}; "
        f"coulomb {coulomb.__version__}, MuJoCo {mujoco.__version__}, Python "
        f"{platform.python_version()}, {platform.machine()}). Command: "
        f"`python benches/peer_step.py --repeats {REPEATS}`. h = 1 ms for every scene; "
        f"best wall time of {REPEATS} runs; "
        f"MuJoCo's loop in C++ by `mujoco.rollout`, coulomb's in Rust by "
        f"`Scene.simulate` (which also records every step's state, impulses and checks). "
        f"'vs MuJoCo': steps/s over MuJoCo's on the same scene in the same run. Load average "
        f"over the last minute when the run ended: {os.getloadavg()[0]:.1f} on "
        f"{os.cpu_count()} cores.",
        "",
        "| scene | solver | steps/s | vs MuJoCo | wall time (s) | figures |",
        "|---|---|---:|---:|---:|---|",
    ]
    peer = {scene: sps for scene, who, sps, _, _ in rows if who.startswith("MuJoCo")}
    for scene, who, sps, sec, figs in rows:
        ratio = f"{sps / peer[scene]:.2f}" if scene in peer else ""
        lines.append(f"| {scene} | {who} | {sps:,.0f} | {ratio} | {sec:.3f} | {figs} |")
    lines.append("")
    lines.append(
        "Exact answers: the ramp box stops at 1.505 m at t = 3.011 s and then does not move "
        "(creep 0); the ball rebounds at e = 0.6 of its speed; the resting box neither drifts "
        "nor sinks."
    )
    lines.append(
        "The tower's boxes must not move at all (exact sticking: drift below 1e-9 m); MuJoCo's "
        "soft contacts let the top box sink. The chain's joint gap is the largest distance "
        "between two hinged ends (MuJoCo's chain is in joint coordinates: no gap by "
        "construction)."
    )
    lines += ["", PROFILE_NOTE]
    table = "\n".join(lines)
    print(table)
    if not args.no_write:
        write_block("step-peers", table)
        print(f"wrote {BENCHMARKS}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
