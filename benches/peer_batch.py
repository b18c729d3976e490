"""Batches against one-at-a-time calls and the peers, written into BENCHMARKS.md ("## Batches").

Run: ``python benches/peer_batch.py`` (about a minute; ``--quick`` for a smoke run, ``--no-write``
to only print). Every figure of a table comes from the same run:

- LCP batches (``coulomb.lcp.solve_batch``) of dense SPD problems at n = 3 and n = 30 with
  10^3 and 10^4 problems: cost per problem on all the cores, on 1 and on 2 threads (the speed-up
  of 2 threads over 1), against a Python loop of ``coulomb.lcp.solve`` and, when installed,
  quantecon's ``lcp_lemke`` called per problem from Python (its per-call cost is what a user
  without a batch API pays).
- friction-contact batches (``coulomb.contact.solve_batch``, NSGS) of one and of ten 3D
  contacts, against a loop of ``coulomb.contact.solve``.
- rollouts (``coulomb.rollout``) of many one-ball scenes (a sphere striking the floor at
  1-5 m/s with e = 0.6, no gravity: the floor-impact scene of ``benches/peer_step.py``) and of
  many resting boxes (``benches/mujoco_scenes.resting_box``), on 1 and 2 threads and against a
  loop of ``Scene.simulate``; the peer is MuJoCo's threaded ``mujoco.rollout.rollout`` on the
  same scenes (one model, one initial state per scene), on 1 and 2 threads.

Each timing is the best of ``--repeats`` runs (wall clock, ``time.perf_counter``); within an LCP
or contact row the candidates (all cores, 1 and 2 threads, the loop, quantecon) are timed in
turn in every repeat, so a row's ratios compare times from the same stretches of the run. The
answers of the batch are checked bitwise against the loop's before anything is timed.
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

# numpy's BLAS threads spin for a while after each product that makes the test data, on the
# cores the batches are timed on: one BLAS thread keeps them out of the measurement
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import coulomb
import numpy as np
from markers import write_block

ROOT = Path(__file__).resolve().parent.parent
HEADING = "## Batches"


def best(fn: Callable[[], object], repeats: int) -> float:
    out = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - start)
    return out


def best_interleaved(fns: list[Callable[[], object]], repeats: int) -> list[float]:
    """The best time of each of `fns`, timed in turn within every repeat: this machine's
    speed drifts over minutes, and rounds that interleave the candidates let each one's best
    come from the same stretches of time, so their ratios do not depend on the drift."""
    out = [math.inf] * len(fns)
    for _ in range(repeats):
        for i, fn in enumerate(fns):
            start = time.perf_counter()
            fn()
            out[i] = min(out[i], time.perf_counter() - start)
    return out


def spd_batch(n: int, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((count, n, n))
    Ms = A @ A.transpose(0, 2, 1) / n + np.eye(n)
    return np.ascontiguousarray(Ms), rng.standard_normal((count, n))


def us(seconds: float, count: int) -> str:
    v = 1e6 * seconds / count
    return f"{v:.3f}" if v < 1 else f"{v:.2f}" if v < 100 else f"{v:.0f}"


def quantecon_loop(Ms: np.ndarray, qs: np.ndarray) -> Callable[[], object] | None:
    """quantecon's ``lcp_lemke`` called on each problem from Python, compiled (numba) before
    it is timed; None when quantecon is not installed."""
    try:
        from quantecon.optimize import lcp_lemke
    except ImportError:
        return None
    lcp_lemke(Ms[0], qs[0])

    def loop() -> None:
        for M, q in zip(Ms, qs, strict=True):
            lcp_lemke(M, q)

    return loop


def lcp_loop(Ms: np.ndarray, qs: np.ndarray) -> None:
    for M, q in zip(Ms, qs, strict=True):
        coulomb.lcp.solve(M, q)


def contact_loop(Ws: np.ndarray, qs: np.ndarray, mu: float) -> None:
    for W, q in zip(Ws, qs, strict=True):
        coulomb.contact.solve(W, q, mu, 3)


def lcp_rows(sizes: list[tuple[int, int]], repeats: int, loop_cap: int) -> list[list[str]]:
    rows = []
    for n, count in sizes:
        Ms, qs = spd_batch(n, count, seed=n * 7 + count)
        k = min(count, loop_cap)
        single = [coulomb.lcp.solve(Ms[i], qs[i]) for i in range(k)]
        check = coulomb.lcp.solve_batch(Ms[:k], qs[:k])
        assert all(r.z.tobytes() == s.z.tobytes() for r, s in zip(check, single, strict=True))
        assert check.success.all()
        qe_loop = quantecon_loop(Ms[:k], qs[:k])
        fns = [partial(coulomb.lcp.solve_batch, Ms, qs, threads=t) for t in (None, 1, 2)]
        fns.append(partial(lcp_loop, Ms[:k], qs[:k]))
        times = best_interleaved(fns + ([qe_loop] if qe_loop else []), repeats)
        t_all, t1, t2 = times[:3]
        t_loop = times[3] / k
        qe = times[4] / k if qe_loop else None
        rows.append([
            "LCP (Lemke)", str(n), f"{count:,}", us(t_all, count), us(t1, count), us(t2, count),
            f"{t1 / t2:.2f}x", f"{1e6 * t_loop:.2f}", "-" if qe is None else f"{1e6 * qe:.2f}",
            f"{t_loop * count / t_all:.1f}x",
        ])
        print(rows[-1], file=sys.stderr)
    return rows


def contact_rows(cases: list[tuple[int, int]], repeats: int, loop_cap: int) -> list[list[str]]:
    rows = []
    for nc, count in cases:
        rng = np.random.default_rng(nc)
        n = 3 * nc
        J = rng.standard_normal((count, n, n + 3))
        Ws = np.ascontiguousarray(J @ J.transpose(0, 2, 1) / (n + 3) + 0.05 * np.eye(n))
        qs = rng.standard_normal((count, n))
        mu = 0.5
        k = min(count, loop_cap)
        single = [coulomb.contact.solve(Ws[i], qs[i], mu, 3) for i in range(k)]
        check = coulomb.contact.solve_batch(Ws[:k], qs[:k], mu, 3)
        assert all(r.impulse.tobytes() == s.impulse.tobytes()
                   for r, s in zip(check, single, strict=True))
        fns = [partial(coulomb.contact.solve_batch, Ws, qs, mu, 3, threads=t)
               for t in (None, 1, 2)]
        times = best_interleaved([*fns, partial(contact_loop, Ws[:k], qs[:k], mu)], repeats)
        t_all, t1, t2 = times[:3]
        t_loop = times[3] / k
        rows.append([
            f"contact (NSGS, {nc} contact{'s' if nc > 1 else ''})", str(n), f"{count:,}",
            us(t_all, count), us(t1, count), us(t2, count), f"{t1 / t2:.2f}x",
            f"{1e6 * t_loop:.2f}", "-", f"{t_loop * count / t_all:.1f}x",
        ])
        print(rows[-1], file=sys.stderr)
    return rows


# -- rollouts --------------------------------------------------------------------------------

def impact_scene(v: float) -> coulomb.Scene:
    s = coulomb.Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    ball = s.add(coulomb.RigidBody3D(mass=0.5, inertia=(0.002,) * 3, position=(0.0, 0.0, 0.11),
                                     velocity=(0.0, 0.0, -v)))
    s.contact(s.attach(ball, coulomb.Sphere(0.1)),
              s.add(coulomb.HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))), e=0.6)
    return s


IMPACT_XML = """
<mujoco>
  <option gravity="0 0 0"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body pos="0 0 0.11">
      <freejoint/>
      <geom type="sphere" size="0.1" mass="0.5"/>
    </body>
  </worldbody>
</mujoco>"""


def resting_box_scene(dx: float) -> coulomb.Scene:
    half = (0.1, 0.1, 0.05)
    a, b, c = (2 * x for x in half)
    inertia = ((b * b + c * c) / 12, (a * a + c * c) / 12, (a * a + b * b) / 12)
    s = coulomb.Scene(dim=3, gravity=(0.0, 0.0, -9.81))
    box = s.add(coulomb.RigidBody3D(mass=1.0, inertia=inertia, position=(dx, 0.0, 0.05)))
    s.contact(s.attach(box, coulomb.Box(half)),
              s.add(coulomb.HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))), mu=0.5)
    return s


RESTING_XML = """
<mujoco>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body pos="0 0 0.05">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.05" mass="1"/>
    </body>
  </worldbody>
</mujoco>"""


def mujoco_rollout(xml: str, count: int, t_end: float, h: float, threads: int,
                   set_state: Callable[[np.ndarray, int, int], None],
                   repeats: int) -> float | None:
    """Seconds for MuJoCo's threaded rollout of `count` initial states of one model."""
    try:
        import mujoco
        from mujoco import rollout
    except ImportError:
        return None
    model = mujoco.MjModel.from_xml_string(xml)
    model.opt.timestep = h
    datas = [mujoco.MjData(model) for _ in range(threads)]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(model, spec)
    state0 = np.empty(size)
    mujoco.mj_getState(model, datas[0], state0, spec)
    states = np.tile(state0, (count, 1))
    for i in range(count):
        set_state(states[i], i, model.nq)
    nstep = round(t_end / h)
    with rollout.Rollout(nthread=threads) as r:
        r.rollout(model, datas, states, nstep=nstep)  # warm-up
        return best(lambda: r.rollout(model, datas, states, nstep=nstep), repeats)


def per_step(t: float | None, total: int) -> str:
    return "-" if t is None else f"{1e6 * t / total:.3f}"


def simulate_loop(scenes: list[coulomb.Scene], t_end: float, h: float) -> None:
    for s in scenes:
        s.simulate(t_end, h)


def rollout_rows(count: int, repeats: int) -> list[list[str]]:
    rows = []
    h = 1e-3
    cases = [
        ("one ball striking the floor", 0.2,
         [impact_scene(1.0 + 4.0 * i / max(count - 1, 1)) for i in range(count)],
         IMPACT_XML,
         lambda st, i, nq: st.__setitem__(1 + nq + 2, -(1.0 + 4.0 * i / max(count - 1, 1)))),
        ("resting box", 0.5,
         [resting_box_scene(0.01 * i) for i in range(count)],
         RESTING_XML,
         lambda st, i, nq: st.__setitem__(1, 0.01 * i)),
    ]
    for name, t_end, scenes, xml, set_state in cases:
        steps = round(t_end / h)
        loop_scenes = scenes[: max(1, count // 4)]
        single = [s.simulate(t_end, h) for s in loop_scenes]
        check = coulomb.rollout(loop_scenes, t_end, h)
        assert all(a.q.tobytes() == b.q.tobytes() for a, b in zip(check, single, strict=True))
        t1, t2 = (best(partial(coulomb.rollout, scenes, t_end, h, threads=t), repeats)
                  for t in (1, 2))
        t_loop = best(partial(simulate_loop, loop_scenes, t_end, h), repeats) / len(loop_scenes)
        m1 = mujoco_rollout(xml, count, t_end, h, 1, set_state, repeats)
        m2 = mujoco_rollout(xml, count, t_end, h, 2, set_state, repeats)
        total = count * steps
        rows.append([
            name, f"{count:,} x {steps}", per_step(t1, total), per_step(t2, total),
            f"{t1 / t2:.2f}x", f"{1e6 * t_loop / steps:.3f}", per_step(m1, total),
            per_step(m2, total),
            "-" if m2 is None else f"{m2 / t2:.2f}x",
        ])
        print(rows[-1], file=sys.stderr)
    return rows


def table(header: list[str], rows: list[list[str]], right: int) -> str:
    out = ["| " + " | ".join(header) + " |",
           "|" + "|".join(["---"] * right + ["---:"] * (len(header) - right)) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, one repeat (smoke run)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-write", action="store_true", help="print only")
    ap.add_argument("--note", default="", help="a line added under the tables (e.g. the load)")
    args = ap.parse_args()
    repeats = 1 if args.quick else args.repeats
    big = 1_000 if args.quick else 10_000
    sizes = [(3, 1_000), (3, big), (30, 1_000), (30, big)]
    loop_cap = 1_000 if args.quick else 5_000
    lcp = lcp_rows(sizes, repeats, loop_cap)
    contact = contact_rows([(1, big), (10, 1_000)], repeats, loop_cap)
    roll = rollout_rows(100 if args.quick else 500, repeats)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cores = os.cpu_count()
    body = (
        f"Generated by `python benches/peer_batch.py` on {now} ({cores} cores, load average "
        f"{load:.1f} at the end of the run). Times per problem in µs, the best of {repeats} "
        f"runs, a row's candidates timed in turn within each run; \"all cores\" is the "
        f"default `threads`. Every batch's answers were "
        f"checked bitwise against the single calls' before timing.\n\n"
        + table(["problems", "n", "batch size", "all cores", "1 thread", "2 threads", "2 vs 1",
                 "single call (Python loop)", "quantecon per call", "batch vs loop"],
                lcp + contact, 1)
        + "\n\nRollouts: `coulomb.rollout` against a loop of `Scene.simulate` and MuJoCo's "
          "threaded `mujoco.rollout` on the same scenes (one model, one initial state per "
          "scene), h = 1 ms; µs per scene-step.\n\n"
        + table(["scenes", "scenes x steps", "coulomb 1 thread", "coulomb 2 threads",
                 "2 vs 1", "Scene.simulate loop", "MuJoCo 1 thread", "MuJoCo 2 threads",
                 "coulomb speed (2 threads)"], roll, 1)
        + (f"\n\n{args.note}" if args.note else "")
    )
    print(body)
    if args.no_write:
        return 0
    write_block("peer-batch", body, heading=HEADING)
    return 0


if __name__ == "__main__":
    sys.exit(main())
