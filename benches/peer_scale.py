"""The stepper's cost against the size of the scene, beside MuJoCo's, written into
BENCHMARKS.md ("The stepper's cost against the size of the scene") with a plot.

    python benches/peer_scale.py [--quick] [--no-write] [--repeats N]

Two scenes of ``benches/peer_step.py``'s spheres (radius 0.05 m, 0.1 kg, mu 0.5, on a grid of
spacing 2.2 radii in a box of a floor and four walls), at 10^2, 10^3, 10^4 and 10^5 spheres,
h = 1 ms, NSGS:

- **pile**: the grid 1 cm above the floor, falling into the box; the figure is the cost per
  contact-step (wall time over the sum of the steps' active contacts);
- **free fall**: the same grid 1000 m up, where nothing touches within the run; the figure is
  the cost per body-step.

coulomb runs ``Scene.simulate`` on all cores (and the pile again on one thread,
``threads=1``: its islands solved one after the other), keeping every 10th step's
record (``record_every=10``; the contacts per step are the mean over those steps), MuJoCo
``mujoco.rollout`` on the same scene (``benches/mujoco_scenes.sphere_pile``), up to 10^4 spheres
(its model of 10^5 free bodies is not built here). Each case runs in its own process, so its
peak resident memory (``ru_maxrss``) is its own; the scene's building in Python is timed apart
(its own column; MuJoCo's model compile is not timed), and coulomb's per-step time leaves out
the fixed cost of a call (the scene read from Python and checked, the stepper built: the time of
a one-step call, given in its own column). Every figure of the table comes from the same run.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

from markers import write_block

sys.path.insert(0, str(Path(__file__).resolve().parent))

ROOT = Path(__file__).resolve().parents[1]
HEADING = "### The stepper's cost against the size of the scene"
PLOT = ROOT / "benches" / "scale.png"
G0 = 9.81
RADIUS = 0.05

#: (spheres, pile steps, free-fall steps); the free falls all last 0.2 s (0.05 s at 10^5), so
#: the bodies reach the same speeds (the search's reach grows with a body's speed)
SIZES = [(100, 1000, 200), (1000, 500, 200), (10_000, 200, 200), (100_000, 200, 50)]
QUICK = [(100, 200, 200), (1000, 100, 200)]
#: coulomb keeps every EVERY-th step's record (its contact count is the mean over those)
EVERY = 10
#: the largest size MuJoCo runs
PEER_MAX = 10_000
#: coulomb's pile again on one thread (its islands solved one after the other)
ONE_THREAD = "coulomb-1-thread"


def coulomb_scene(count: int, lift: float):
    """the pile of ``benches/peer_step.py``, its grid raised by ``lift`` metres."""
    from coulomb import HalfSpace, RigidBody3D, Scene, Sphere

    side = math.ceil(count ** (1 / 3))
    spacing = 2.2 * RADIUS
    half = side * spacing / 2 + RADIUS
    scene = Scene(dim=3, gravity=(0.0, 0.0, -G0))
    walls = [scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))] + [
        scene.add(HalfSpace(p, n)) for p, n in (
            ((-half, 0.0, 0.0), (1.0, 0.0, 0.0)), ((half, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            ((0.0, -half, 0.0), (0.0, 1.0, 0.0)), ((0.0, half, 0.0), (0.0, -1.0, 0.0)))]
    inertia = 0.4 * 0.1 * RADIUS * RADIUS
    for k in range(count):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        pos = (-half + RADIUS + spacing * (i + 0.5), -half + RADIUS + spacing * (j + 0.5),
               lift + RADIUS + 0.01 + spacing * l)
        body = scene.add(RigidBody3D(mass=0.1, inertia=(inertia,) * 3, position=pos))
        shape = scene.attach(body, Sphere(RADIUS))
        for w in walls:
            scene.contact(shape, w, mu=0.5)
    scene.contact_spheres(mu=0.5)
    return scene


def run_case(who: str, kind: str, count: int, steps: int, repeats: int) -> dict:
    """one case, in this process: the best wall time of ``repeats`` runs."""
    lift = 1000.0 if kind == "fall" else 0.0
    h = 1e-3
    out: dict = {"who": who, "kind": kind, "bodies": count, "steps": steps}
    if who.startswith("coulomb"):
        # each step's islands on all the cores, or on one thread
        threads = 1 if who == ONE_THREAD else None
        # the fixed costs of a call (the scene's data read from Python and checked, the
        # stepper built) are timed by a one-step call and taken out of the run's time
        build, setup, best, tr = math.inf, math.inf, math.inf, None
        for _ in range(repeats):
            start = time.perf_counter()
            scene = coulomb_scene(count, lift)
            build = min(build, time.perf_counter() - start)
            start = time.perf_counter()
            scene.simulate(h, h, "nsgs", threads=threads)
            setup = min(setup, time.perf_counter() - start)
            start = time.perf_counter()
            tr = scene.simulate(steps * h, h, "nsgs", record_every=EVERY, threads=threads)
            best = min(best, time.perf_counter() - start)
        assert tr is not None
        out["setup"] = setup
        out["build"] = build
        out["seconds"] = best - setup * (1.0 - 1.0 / steps) if best > setup else best
        # the recorded steps' mean (every EVERY-th step and the last)
        out["contacts_per_step"] = float(tr.active.mean())
        out["success"] = bool(tr.success)
    else:
        import mujoco_scenes as mj

        run = mj.sphere_pile(count, h, t_end=steps * h, lift=lift, repeats=repeats)
        out["seconds"] = run.seconds
        out["steps"] = run.steps
    out["max_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def case_in_child(who: str, kind: str, count: int, steps: int, repeats: int) -> dict:
    cmd = [sys.executable, __file__, "--case", who, kind, str(count), str(steps),
           "--repeats", str(repeats)]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def fmt(x: float) -> str:
    return f"{x:.3g}" if x < 100 else f"{x:,.0f}"


def table(results: list[dict], repeats: int) -> str:
    by = {(r["who"], r["kind"], r["bodies"]): r for r in results}
    sizes = sorted({r["bodies"] for r in results})
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, cwd=ROOT, check=False).stdout.strip()
    except OSError:
        rev = "unknown"
    import coulomb

    lines = [
        HEADING, "",
        f"Generated by `benches/peer_scale.py` on "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC (revision {rev}; "
        f"coulomb {coulomb.__version__}, Python {platform.python_version()}). Command: "
        f"`python benches/peer_scale.py --repeats {repeats}`. Best wall time of {repeats} "
        f"runs, each case in its own process; h = 1 ms, NSGS; MuJoCo by `mujoco.rollout` on the "
        f"same scene up to {PEER_MAX:,} spheres. Load average over the last minute when the run "
        f"ended: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores.",
        "",
        "| spheres | scene | steps | contacts per step | coulomb us per step | us per "
        "contact-step | us per body-step | MuJoCo us per step | vs MuJoCo | coulomb on 1 "
        "thread, us per step | all cores vs 1 thread | coulomb setup "
        "(s) | scene built in Python (s) | coulomb peak memory (MB) |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for kind, name in (("pile", "pile"), ("fall", "free fall")):
        for n in sizes:
            c = by.get(("coulomb", kind, n))
            if c is None:
                continue
            per_step = 1e6 * c["seconds"] / c["steps"]
            contacts = c["contacts_per_step"]
            per_contact = fmt(per_step / contacts) if contacts > 0 else "-"
            m = by.get(("mujoco", kind, n))
            m_step = 1e6 * m["seconds"] / m["steps"] if m else None
            one = by.get((ONE_THREAD, kind, n))
            one_step = 1e6 * one["seconds"] / one["steps"] if one else None
            lines.append(
                f"| {n:,} | {name} | {c['steps']} | {contacts:.1f} | {fmt(per_step)} | "
                f"{per_contact} | {fmt(per_step / n)} | "
                f"{fmt(m_step) if m_step else '-'} | "
                f"{f'{m_step / per_step:.2f}x' if m_step else '-'} | "
                f"{fmt(one_step) if one_step else '-'} | "
                f"{f'{one_step / per_step:.2f}x' if one_step else '-'} | {c['setup']:.3g} | "
                f"{c['build']:.3g} | "
                f"{c['max_rss_mb']:,.0f} |")
    lines += ["", "![cost per body-step and per contact-step against the number of spheres]"
              "(benches/scale.png)", ""]
    return "\n".join(lines)


def plot(results: list[dict]) -> str:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib missing: no plot"
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for who, style in (("coulomb", "-o"), ("mujoco", "--s")):  # all cores
        for kind, label, per in (("fall", "free fall, per body-step", "body"),
                                 ("pile", "pile, per contact-step", "contact")):
            rows = sorted((r for r in results if r["who"] == who and r["kind"] == kind),
                          key=lambda r: r["bodies"])
            xs, ys = [], []
            for r in rows:
                per_step = 1e6 * r["seconds"] / r["steps"]
                if per == "body":
                    y = per_step / r["bodies"]
                elif who == "coulomb" and r["contacts_per_step"] > 0:
                    y = per_step / r["contacts_per_step"]
                else:
                    continue
                xs.append(r["bodies"])
                ys.append(y)
            if xs:
                ax.loglog(xs, ys, style, label=f"{'MuJoCo' if who == 'mujoco' else who}: {label}")
    ax.set_xlabel("spheres")
    ax.set_ylabel("microseconds")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(PLOT, dpi=110)
    return f"plot written to {PLOT}"


def write(block: str) -> None:
    write_block("peer-scale", block)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="100 and 1000 spheres, short runs")
    ap.add_argument("--no-write", action="store_true", help="print only")
    ap.add_argument("--repeats", type=int, default=2, help="timed runs per case, best kept")
    ap.add_argument("--case", nargs=4, metavar=("WHO", "KIND", "N", "STEPS"),
                    help=argparse.SUPPRESS)
    args = ap.parse_args()
    repeats = max(1, args.repeats)
    if args.case:
        who, kind, n, steps = args.case
        print(json.dumps(run_case(who, kind, int(n), int(steps), repeats)))
        return 0
    results = []
    for n, pile_steps, fall_steps in (QUICK if args.quick else SIZES):
        for kind, steps in (("pile", pile_steps), ("fall", fall_steps)):
            for who in ("coulomb", ONE_THREAD, "mujoco"):
                if (who == "mujoco" and n > PEER_MAX) or (who == ONE_THREAD and kind != "pile"):
                    continue
                r = case_in_child(who, kind, n, steps, 1 if n >= 100_000 else repeats)
                print(f"{who:16s} {kind:5s} {n:>7,} spheres: {r['seconds']:.3f} s for "
                      f"{r['steps']} steps, peak {r['max_rss_mb']:,.0f} MB", file=sys.stderr)
                results.append(r)
    block = table(results, repeats)
    print(block)
    print(plot(results), file=sys.stderr)
    if not args.no_write:
        write(block)
    return 0


if __name__ == "__main__":
    sys.exit(main())
