#!/usr/bin/env python3
"""Benchmark coulomb's contact solvers (NSGS and the robust mode ``prox``) on the FCLib subset
and the Siconos friction-contact test files, against Siconos 4.4 (NSGS and PROX) when the
system Python has ``siconos.numerics`` (Debian ``python3-siconos``), in the same run.

Every answer is judged the same way: ``error_q = ||F_nat(r)|| / ||q||`` recomputed here in
numpy from the returned impulses (../shared/data/fclib/SOURCE.md, "Error measure"); a run
succeeds when ``error_q <= tol``. Each solver stops on its own verdict: coulomb's NSGS and
prox when ``scaled_error <= tol`` and ``error_q <= max(tol, error_q_floor)`` (the rule of
``ContactResult.success``), Siconos on its own ``fc3d_compute_error``. Times are wall-clock
seconds of one solve (coulomb: ``solve_time`` of the Rust core; Siconos: around
``fc3d_driver``, dense W unless scipy.sparse is accepted). Siconos is run for 3D problems only.

Writes a Markdown table into BENCHMARKS.md between ``<!-- contact-peers:begin -->`` and
``<!-- contact-peers:end -->`` and a Dolan-More performance profile to
``benches/contact_profile.png`` (needs matplotlib).

Examples::

    python benches/peer_contact.py --quick --output /tmp/contact.md
    python benches/peer_contact.py                      # every problem, both tolerances
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from markers import write_block

REPO_ROOT = Path(__file__).resolve().parents[1]
SYSTEM_PYTHON = "/usr/bin/python3"
QUICK = (
    "BoxesStack1-i100000-32",
    "OneObject-i100000-499",
    "local_problem_test",
    "Capsules-i97-269",
    "NESpheres_10_1",
    "Box_Stacks-i0122-82-5",
)
# read but not benchmarked by default: too slow for a short run on a shared machine
SLOW = ("fc2d_granularflowonwall_02020_00213", "RockPile_tob1")


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def data_dir() -> Path:
    env = os.environ.get("COULOMB_DATA")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "data"


@dataclass
class Problem:
    name: str
    source: str
    W: np.ndarray
    q: np.ndarray
    mu: np.ndarray
    dim: int

    @property
    def nc(self) -> int:
        return int(self.mu.shape[0])


@dataclass
class Run:
    problem: str
    solver: str
    tol: float
    iterations: int | None
    error_q: float
    seconds: float
    note: str = ""

    @property
    def success(self) -> bool:
        return bool(np.isfinite(self.error_q) and self.error_q <= self.tol)


def project_cone(v: np.ndarray, mu: float) -> np.ndarray:
    n, t = v[0], v[1:]
    s = float(np.linalg.norm(t))
    if s <= mu * n:
        return v
    if mu * s <= -n:
        return np.zeros_like(v)
    a = (n + mu * s) / (1 + mu * mu)
    return np.concatenate([[a], mu * a * t / s])


def error_q(p: Problem, r: np.ndarray) -> float:
    """De Saxce's natural-map residual divided by ||q|| (numpy, independent of the solvers)."""
    r = np.asarray(r, dtype=float).reshape(-1)
    if r.shape[0] != p.q.shape[0] or not np.isfinite(r).all():
        return float("inf")
    u = p.W @ r + p.q
    d = p.dim
    res = np.empty_like(r)
    for i, m in enumerate(p.mu):
        s = slice(i * d, (i + 1) * d)
        v = r[s] - u[s]
        v[0] -= m * np.linalg.norm(u[s][1:])
        res[s] = r[s] - project_cone(v, float(m))
    qn = float(np.linalg.norm(p.q))
    return float(np.linalg.norm(res) / (qn if qn >= 1e-300 else 1.0))


def load_problems(names: set[str] | None, include_slow: bool) -> list[Problem]:
    from coulomb.io import FrictionContactProblem, read_fclib, read_siconos_fc

    root = data_dir()
    out: list[Problem] = []
    seen: set[str] = set()
    for f in sorted((root / "fclib").glob("**/*.hdf5")):
        if (f.stem in SLOW and not include_slow) or (names and f.stem not in names):
            continue
        try:
            p = read_fclib(f)
        except Exception as exc:  # refused kinds (rolling) are reported, not benchmarked
            log(f"skip {f.name}: {type(exc).__name__}: {exc}")
            continue
        out.append(Problem(p.name, "fclib", p.W.toarray(), p.q, p.mu, p.dim))
        seen.add(p.name.replace(".hdf5", ""))
    for f in sorted((root / "siconos-fc").glob("*.dat")):
        stem = f.stem.replace(".hdf5", "")
        if stem in seen or (stem in SLOW and not include_slow) or (names and stem not in names):
            continue
        try:
            p = read_siconos_fc(f)
        except Exception as exc:
            log(f"skip {f.name}: {type(exc).__name__}: {exc}")
            continue
        if isinstance(p, FrictionContactProblem):
            out.append(Problem(stem, "siconos-fc", p.W, p.q, p.mu, p.dim))
    return out


def run_coulomb(p: Problem, method: str, tol: float, max_iter: int) -> Run:
    from coulomb import contact

    t = time.perf_counter()
    r = contact.solve(p.W, p.q, p.mu, p.dim, method=method, tol=tol, max_iter=max_iter)
    wall = time.perf_counter() - t
    return Run(
        p.name,
        f"coulomb {method}",
        tol,
        int(r.iterations),
        error_q(p, r.impulse),
        float(r.solve_time) if "solve_time" in r else wall,
        "" if r.success else r.status,
    )


SICONOS_SCRIPT = r"""
import json, sys, time
import numpy as np
import siconos.numerics as sn
data = np.load(sys.argv[1])
tol, max_iter = float(sys.argv[2]), int(sys.argv[3])
W, q, mu = data["W"], data["q"], data["mu"]
nc = mu.shape[0]
out = {}
for name, sid in (("nsgs", sn.SICONOS_FRICTION_3D_NSGS), ("prox", sn.SICONOS_FRICTION_3D_PROX)):
    try:
        p = sn.FrictionContactProblem(3, nc, W, q, mu)
        so = sn.SolverOptions(sid)
        so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter if name == "nsgs" else 1000
        so.dparam[sn.SICONOS_DPARAM_TOL] = tol
        r = np.zeros(3 * nc)
        u = np.zeros(3 * nc)
        t = time.perf_counter()
        info = sn.fc3d_driver(p, r, u, so)
        dt = time.perf_counter() - t
        out[name] = {"info": int(info), "iter": int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                     "seconds": dt, "r": r.tolist()}
    except Exception as exc:
        out[name] = {"error": f"{type(exc).__name__}: {exc}"}
print(json.dumps(out))
"""


def siconos_available() -> bool:
    if not Path(SYSTEM_PYTHON).exists():
        return False
    probe = subprocess.run(
        [SYSTEM_PYTHON, "-c", "import siconos.numerics"], capture_output=True, timeout=60
    )
    return probe.returncode == 0


def run_siconos(p: Problem, tol: float, max_iter: int, timeout: float) -> list[Run]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "problem.npz"
        np.savez(path, W=p.W, q=p.q, mu=p.mu)
        script = Path(tmp) / "run.py"
        script.write_text(SICONOS_SCRIPT)
        try:
            done = subprocess.run(
                [SYSTEM_PYTHON, str(script), str(path), repr(tol), str(max_iter)],
                capture_output=True,
                text=True,
                timeout=timeout,
            )
        except subprocess.TimeoutExpired:
            return [
                Run(p.name, f"siconos {m}", tol, None, float("inf"), timeout, "timeout")
                for m in ("nsgs", "prox")
            ]
    if done.returncode != 0:
        msg = done.stderr.strip().splitlines()[-1:] or ["failed"]
        return [
            Run(p.name, f"siconos {m}", tol, None, float("inf"), 0.0, msg[0][:60])
            for m in ("nsgs", "prox")
        ]
    res = json.loads(done.stdout.strip().splitlines()[-1])
    runs = []
    for m in ("nsgs", "prox"):
        d = res[m]
        if "error" in d:
            runs.append(Run(p.name, f"siconos {m}", tol, None, float("inf"), 0.0, d["error"][:60]))
        else:
            runs.append(
                Run(
                    p.name,
                    f"siconos {m}",
                    tol,
                    d["iter"],
                    error_q(p, np.array(d["r"])),
                    d["seconds"],
                    "" if d["info"] == 0 else f"info {d['info']}",
                )
            )
    return runs


def fmt_time(s: float) -> str:
    return f"{s * 1e3:.1f} ms" if s < 1 else f"{s:.2f} s"


def table(problems: list[Problem], runs: list[Run], solvers: list[str], tol: float) -> list[str]:
    head = "| problem | nc | " + " | ".join(solvers) + " |"
    lines = [
        f"Tolerance {tol:g} (success: recomputed error_q <= {tol:g}); each cell: "
        "iterations / error_q / time, a cross marks a failure.",
        "",
        head,
        "|" + "---|" * (len(solvers) + 2),
    ]
    index = {(r.problem, r.solver, r.tol): r for r in runs}
    for p in problems:
        cells = []
        for s in solvers:
            r = index.get((p.name, s, tol))
            if r is None:
                cells.append("n/a")
                continue
            it = "-" if r.iterations is None else str(r.iterations)
            mark = "" if r.success else " ✗"
            cells.append(f"{it} / {r.error_q:.1e} / {fmt_time(r.seconds)}{mark}")
        lines.append(f"| {p.name} | {p.nc} | " + " | ".join(cells) + " |")
    return lines


def ratios(runs: list[Run], tol: float) -> list[str]:
    """Total time of coulomb's best solver over Siconos NSGS where both succeed."""
    out = []
    by = {}
    for r in runs:
        if r.tol == tol:
            by.setdefault(r.problem, {})[r.solver] = r
    for ours in ("coulomb nsgs", "coulomb prox"):
        for theirs in ("siconos nsgs", "siconos prox"):
            both = [
                (d[ours].seconds, d[theirs].seconds)
                for d in by.values()
                if ours in d and theirs in d and d[ours].success and d[theirs].success
            ]
            if both:
                a = sum(x for x, _ in both)
                b = sum(y for _, y in both)
                out.append(
                    f"- tol {tol:g}: {ours} {fmt_time(a)} vs {theirs} {fmt_time(b)} in total on "
                    f"the {len(both)} problems both solve: {theirs} / {ours} = {b / a:.2f}"
                )
    return out


def profile(runs: list[Run], solvers: list[str], tols: list[float], path: Path) -> str:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib missing: no performance profile"
    fig, axes = plt.subplots(1, len(tols), figsize=(5 * len(tols), 4), squeeze=False)
    for ax, tol in zip(axes[0], tols, strict=True):
        by: dict[str, dict[str, float]] = {}
        for r in runs:
            if r.tol == tol:
                t = r.seconds if r.success else np.inf
                by.setdefault(r.problem, {})[r.solver] = max(t, 1e-6)
        ratios_by_solver: dict[str, list[float]] = {s: [] for s in solvers}
        for times in by.values():
            best = min(times.values())
            for s in solvers:
                t = times.get(s, np.inf)
                ratios_by_solver[s].append(t / best if np.isfinite(best) else np.inf)
        taus = np.logspace(0, 4, 200)
        for s, rs in ratios_by_solver.items():
            arr = np.array(rs)
            if arr.size:
                ax.step(taus, [(arr <= tau).mean() for tau in taus], where="post", label=s)
        ax.set_xscale("log")
        ax.set_xlabel("time / best time (tau)")
        ax.set_ylabel("fraction of problems solved within tau")
        ax.set_title(f"Dolan-More profile, tol {tol:g}")
        ax.set_ylim(0, 1.02)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    shown = path.relative_to(REPO_ROOT) if path.is_relative_to(REPO_ROOT) else path
    return f"Dolan-More performance profile: `{shown}`"


def write_markers(target: Path, body: str) -> None:
    write_block("contact-peers", body, target, heading="## Contact solvers against peers")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help=f"only {', '.join(QUICK)}")
    ap.add_argument("--problems", help="comma-separated problem names")
    ap.add_argument("--include-slow", action="store_true", help=f"also {', '.join(SLOW)}")
    ap.add_argument("--tols", default="1e-4,1e-8")
    ap.add_argument("--nsgs-max-iter", type=int, default=10000)
    ap.add_argument("--prox-max-iter", type=int, default=200)
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--siconos-timeout", type=float, default=120.0)
    ap.add_argument("--output", type=Path, default=REPO_ROOT / "BENCHMARKS.md")
    ap.add_argument("--plot", type=Path, default=REPO_ROOT / "benches" / "contact_profile.png")
    args = ap.parse_args()
    names = set(QUICK) if args.quick else None
    if args.problems:
        names = set(args.problems.split(","))
    tols = [float(t) for t in args.tols.split(",")]
    problems = load_problems(names, args.include_slow)
    with_siconos = not args.no_siconos and siconos_available()
    solvers = ["coulomb nsgs", "coulomb prox"]
    if with_siconos:
        solvers += ["siconos nsgs", "siconos prox"]
    runs: list[Run] = []
    for p in problems:
        for tol in tols:
            log(f"{p.name} (nc {p.nc}) tol {tol:g}")
            runs.append(run_coulomb(p, "nsgs", tol, args.nsgs_max_iter))
            runs.append(run_coulomb(p, "prox", tol, args.prox_max_iter))
            if with_siconos and p.dim == 3:
                runs.extend(run_siconos(p, tol, args.nsgs_max_iter, args.siconos_timeout))
    lines = [
        f"Generated by `python benches/peer_contact.py {shlex.join(sys.argv[1:])}` on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; NSGS at most "
        f"{args.nsgs_max_iter} sweeps (coulomb and Siconos), coulomb prox at most "
        f"{args.prox_max_iter} Newton steps, Siconos PROX its default inner solver and 1000 "
        "outer iterations. Zero initial impulses. Siconos: "
        + (
            "`python3-siconos` from the system Python, given a dense W (no scipy there): its "
            "NSGS is slower on the larger problems than with its sparse-block storage "
            "(../shared/data/fclib/SOURCE.md), so the ratios below flatter coulomb there."
            if with_siconos
            else "not run."
        )
        + " Global FCLib problems are reduced with `coulomb.contact.assemble`.",
        "",
    ]
    for tol in tols:
        lines += [*table(problems, runs, solvers, tol), ""]
    rat = [line for tol in tols for line in ratios(runs, tol)]
    if rat:
        lines += ["Time ratios:", "", *rat, ""]
    lines.append(profile(runs, solvers, tols, args.plot))
    body = "\n".join(lines)
    write_markers(args.output, body)
    print(body)


if __name__ == "__main__":
    main()
