#!/usr/bin/env python3
"""coulomb's NSGS against Siconos 4.4's NSGS, sweep for sweep, on the 3D local problems of the
FCLib subset and the Siconos friction-contact set, in one run.

Two solves per solver and problem, both from zero impulses:

- to tolerance: tol 1e-8, at most ``--max-iter`` sweeps, coulomb's plain sweeps
  (``sticking=False``) and its default (the sticking-set solve when the sweeps slow down);
  each solver stops on its own measure
  (coulomb: ``scaled_error``; Siconos: its ``fc3d_compute_error``), and both answers are judged
  by the same ``error_q = ||F_nat(r)|| / ||q||`` recomputed here in numpy;
- per sweep (coulomb's plain sweeps): exactly ``--sweeps`` sweeps (a tolerance no iterate
  reaches), time / sweeps done
  (a problem solved to rounding stops earlier), the best of ``--repeat`` solves per solver and
  storage (the machine may be shared: the best run is the least disturbed one).

coulomb is given W as scipy CSR (read as block CSR) and as a dense array (copied once into
block CSR when its tiles are mostly zero). Siconos (``python3-siconos`` in the system Python,
run in a subprocess) is given its sparse-block storage (SBM) when the problem is a Siconos
``.dat`` file stored that way, scipy's sparse W (Siconos' CSC storage) otherwise, and a dense W.
Siconos NSGS runs its defaults: the hybrid Newton local solver and a light error per sweep
with the full error at the end. Times are wall-clock seconds of one solve (coulomb:
``solve_time`` of the Rust core; Siconos: around ``fc3d_driver``).

Writes a Markdown table into BENCHMARKS.md between ``<!-- nsgs-peers:begin -->`` and
``<!-- nsgs-peers:end -->``::

    python benches/peer_nsgs.py                 # every problem
    python benches/peer_nsgs.py --problems Capsules-i97-269 --output /tmp/nsgs.md
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
import scipy.sparse as sp
from markers import write_block

REPO_ROOT = Path(__file__).resolve().parents[1]
SYSTEM_PYTHON = "/usr/bin/python3"


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def data_dir() -> Path:
    env = os.environ.get("COULOMB_DATA")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "data"


@dataclass
class Problem:
    name: str
    W: sp.csr_array
    q: np.ndarray
    mu: np.ndarray
    dat: Path | None  # a Siconos .dat file stored sparse-block, read by Siconos itself

    @property
    def nc(self) -> int:
        return int(self.mu.shape[0])


def error_q(p: Problem, r: np.ndarray) -> float:
    """De Saxce's natural-map residual divided by ||q|| (numpy, independent of the solvers)."""
    r = np.asarray(r, dtype=float).reshape(-1)
    if r.shape != p.q.shape or not np.isfinite(r).all():
        return float("inf")
    u = p.W @ r + p.q
    res = np.empty_like(r)
    for i, m in enumerate(p.mu):
        s = slice(3 * i, 3 * i + 3)
        v = r[s] - u[s]
        v[0] -= m * np.linalg.norm(u[s][1:])
        n, t = v[0], v[1:]
        nt = float(np.linalg.norm(t))
        if nt <= m * n:
            pv = v
        elif m * nt <= -n:
            pv = np.zeros(3)
        else:
            a = (n + m * nt) / (1 + m * m)
            pv = np.concatenate([[a], m * a * t / nt])
        res[s] = r[s] - pv
    qn = float(np.linalg.norm(p.q))
    return float(np.linalg.norm(res) / (qn if qn >= 1e-300 else 1.0))


def sbm_storage(path: Path) -> bool:
    """whether a Siconos .dat friction-contact file stores W sparse-block (storage type 1)."""
    with open(path) as fh:
        head = [fh.readline().split() for _ in range(3)]
    return len(head) == 3 and head[0] == ["3"] and head[2][:1] == ["1"]


def load(names: set[str] | None) -> list[Problem]:
    from coulomb.io import FrictionContactProblem, read_fclib, read_siconos_fc

    root = data_dir()
    out: list[Problem] = []
    seen: set[str] = set()
    dats = {f.stem.replace(".hdf5", ""): f for f in (root / "siconos-fc").glob("*.dat")}
    for f in sorted((root / "fclib").glob("**/*.hdf5")):
        stem = f.stem.replace(".hdf5", "")
        if names and stem not in names:
            continue
        try:
            p = read_fclib(f)
        except Exception as exc:  # refused kinds (rolling friction) are reported
            log(f"skip {f.name}: {type(exc).__name__}")
            continue
        if p.dim != 3:
            continue
        dat = dats.get(stem)
        out.append(
            Problem(stem, sp.csr_array(p.W), np.asarray(p.q), np.asarray(p.mu),
                    dat if dat is not None and sbm_storage(dat) else None)
        )
        seen.add(stem)
    for stem, f in sorted(dats.items()):
        if stem in seen or (names and stem not in names):
            continue
        try:
            p = read_siconos_fc(f)
        except Exception as exc:
            log(f"skip {f.name}: {type(exc).__name__}")
            continue
        if isinstance(p, FrictionContactProblem) and p.dim == 3:
            out.append(
                Problem(stem, sp.csr_array(p.W), np.asarray(p.q), np.asarray(p.mu),
                        f if sbm_storage(f) else None)
            )
    return out


def run_coulomb(p: Problem, W, tol: float, max_iter: int, repeat: int = 1,
                sticking: bool = False) -> dict:
    """one solve's figures; with ``repeat`` > 1 the least time per sweep of that many. Plain
    sweeps unless ``sticking`` (coulomb's default, the sticking-set solve when the sweeps slow
    down): Siconos's NSGS makes plain sweeps, so those are compared one for one."""
    from coulomb import contact

    best: dict = {}
    for _ in range(repeat):
        r = contact.solve(W, p.q, p.mu, 3, method="nsgs", tol=tol, max_iter=max_iter,
                          sticking=sticking)
        out = {
            "iter": int(r.iterations),
            "seconds": float(r.solve_time),
            "error_q": error_q(p, r.impulse),
            "own": bool(r.success),
        }
        def per(d: dict) -> float:
            return d["seconds"] / max(d["iter"], 1)

        if not best or per(out) < per(best):
            best = out
    return best


SICONOS_SCRIPT = r"""
import json, sys, time
import numpy as np
import scipy.sparse as sp
import siconos.numerics as sn
data = np.load(sys.argv[1], allow_pickle=False)
dat, sweeps, max_iter = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
repeat = int(sys.argv[5])
W = sp.csc_matrix((data["data"], data["indices"], data["indptr"]), shape=tuple(data["shape"]))
q, mu = data["q"], data["mu"]
nc = mu.shape[0]
def problem(kind):
    if kind == "sbm":
        return sn.frictionContact_new_from_filename(dat)
    if kind == "csc":
        Wc = W.tocoo()
        Wc = sp.coo_matrix((Wc.data, (Wc.row.astype(np.int64), Wc.col.astype(np.int64))),
                           shape=Wc.shape)
        return sn.FrictionContactProblem(3, nc, Wc, q, mu)
    return sn.FrictionContactProblem(3, nc, W.toarray(), q, mu)
out = {}
import warnings
warnings.simplefilter("ignore")
for kind in ("sbm" if dat else "csc", "dense"):
    for what, tol, iters in (("tol", 1e-8, max_iter), ("sweeps", 1e-300, sweeps)):
        for _ in range(repeat if what == "sweeps" else 1):
            p = problem(kind)
            so = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
            so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = iters
            so.dparam[sn.SICONOS_DPARAM_TOL] = tol
            r = np.zeros(3 * nc)
            u = np.zeros(3 * nc)
            t = time.perf_counter()
            info = sn.fc3d_driver(p, r, u, so)
            dt = time.perf_counter() - t
            done = int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE])
            key = kind + "/" + what
            old = out.get(key)
            if old is None or dt / max(done, 1) < old["seconds"] / max(old["iter"], 1):
                out[key] = {"info": int(info), "iter": done, "seconds": dt, "r": r.tolist()}
print(json.dumps(out))
"""


def run_siconos(p: Problem, sweeps: int, max_iter: int, timeout: float, repeat: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "p.npz"
        Wc = p.W.tocsc()
        np.savez(path, data=Wc.data, indices=Wc.indices, indptr=Wc.indptr,
                 shape=np.array(Wc.shape), q=p.q, mu=p.mu)
        script = Path(tmp) / "run.py"
        script.write_text(SICONOS_SCRIPT)
        try:
            done = subprocess.run(
                [SYSTEM_PYTHON, str(script), str(path), str(p.dat or ""), str(sweeps),
                 str(max_iter), str(repeat)],
                capture_output=True, text=True, timeout=timeout,
            )
        except subprocess.TimeoutExpired:
            return {}
    if done.returncode != 0:
        log(f"siconos failed on {p.name}: {done.stderr.strip().splitlines()[-1:]}")
        return {}
    res = json.loads(done.stdout.strip().splitlines()[-1])
    for d in res.values():
        d["error_q"] = error_q(p, np.array(d.pop("r")))
        d["own"] = d["info"] == 0
    return res


def us(seconds: float, sweeps: int) -> str:
    return f"{seconds / sweeps * 1e6:.1f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--problems", help="comma-separated problem names")
    ap.add_argument("--sweeps", type=int, default=200, help="sweeps of the per-sweep solve")
    ap.add_argument("--max-iter", type=int, default=10000)
    ap.add_argument("--timeout", type=float, default=600.0)
    ap.add_argument("--repeat", type=int, default=5,
                    help="per-sweep solves per solver and storage, the best kept")
    ap.add_argument("--output", type=Path, default=REPO_ROOT / "BENCHMARKS.md")
    args = ap.parse_args()
    names = set(args.problems.split(",")) if args.problems else None
    problems = load(names)
    rows = []
    ratios = []
    for p in problems:
        log(f"{p.name} (nc {p.nc})")
        dense = p.W.toarray()
        c_tol = run_coulomb(p, p.W, 1e-8, args.max_iter)
        c_default = run_coulomb(p, p.W, 1e-8, args.max_iter, sticking=True)
        c_sw = run_coulomb(p, p.W, 1e-300, args.sweeps, args.repeat)
        c_dense = run_coulomb(p, dense, 1e-300, args.sweeps, args.repeat)
        s = run_siconos(p, args.sweeps, args.max_iter, args.timeout, args.repeat)
        sk = "sbm" if p.dat else "csc"
        st, ss, sd = s.get(f"{sk}/tol"), s.get(f"{sk}/sweeps"), s.get("dense/sweeps")

        def verdict(d: dict | None) -> str:
            if d is None:
                return "-"
            own = "converged" if d["own"] else "not converged"
            mark = "" if d["error_q"] <= 1e-8 else " ✗"
            return f"{d['iter']} / {d['error_q']:.1e}{mark} ({own})"

        per_c = c_sw["seconds"] / max(c_sw["iter"], 1)
        per_cd = c_dense["seconds"] / max(c_dense["iter"], 1)
        per_s = ss["seconds"] / ss["iter"] if ss and ss["iter"] else float("nan")
        per_sd = sd["seconds"] / sd["iter"] if sd and sd["iter"] else float("nan")
        # against the faster of Siconos' two storages
        best = np.nanmin([per_s, per_sd]) if np.isfinite([per_s, per_sd]).any() else np.nan
        ratio = best / per_c if np.isfinite(best) else float("nan")
        ratios.append(ratio)
        rows.append(
            f"| {p.name} | {p.nc} | {verdict(c_tol)} | {verdict(c_default)} | {verdict(st)} | "
            f"{per_c * 1e6:.2f} | {per_cd * 1e6:.2f} | "
            f"{per_s * 1e6:.2f} ({sk}) | {per_sd * 1e6:.2f} | {ratio:.2f}x | "
            f"{per_c / p.nc * 1e9:.0f} |"
        )
        log(rows[-1])
    finite = [r for r in ratios if np.isfinite(r)]
    lines = [
        f"Generated by `python benches/peer_nsgs.py {shlex.join(sys.argv[1:])}` on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. To tolerance: sweeps / "
        f"recomputed error_q at tol 1e-8 (at most {args.max_iter} sweeps; ✗: error_q > 1e-8), "
        "and whether the solver's own stopping test passed (coulomb: scaled_error <= 1e-8, "
        "its success; Siconos: its error <= 1e-8, info 0); coulomb's plain sweeps "
        "(`sticking=False`, Siconos' method) and its default (the sticking-set solve when the "
        "sweeps slow down). "
        f"Per sweep: microseconds per sweep of a solve of {args.sweeps} sweeps from zero "
        "(divided by the sweeps each solver reports: a problem solved to rounding stops "
        f"earlier), the best of {args.repeat} solves per solver and storage, "
        "coulomb given W as scipy CSR and dense, "
        "Siconos its sparse-block storage (sbm) where the problem is a Siconos file stored "
        "so, else its CSC storage (csc), and dense. Speed: the faster of Siconos' two per "
        "sweep / coulomb's (CSR) per sweep; Siconos' time is that of its whole driver call "
        "(its setup included), so on the smallest problems the ratio flatters coulomb.",
        "",
        "| problem | nc | coulomb plain sweeps to 1e-8 | coulomb default to 1e-8 | "
        "Siconos to 1e-8 | coulomb us/sweep (CSR) | "
        "coulomb us/sweep (dense W) | Siconos us/sweep (sparse) | Siconos us/sweep (dense) | "
        "speed | coulomb ns per contact-sweep |",
        "|---|---:|---|---|---|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"Speed per sweep against Siconos' faster storage: min {min(finite):.2f}x, "
        f"median {float(np.median(finite)):.2f}x over {len(finite)} problems."
        if finite
        else "Siconos not run.",
    ]
    body = "\n".join(lines)
    write_block("nsgs-peers", body, args.output,
                heading="### NSGS against Siconos NSGS, sweep for sweep")
    print(body)


if __name__ == "__main__":
    main()
