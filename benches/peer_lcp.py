#!/usr/bin/env python3
"""Benchmark coulomb's Lemke LCP solver against peer Python-callable solvers.

Runs the same seeded problems (see ``lcp_problems.py``) in one process through
coulomb, QuantEcon, lemkelcp and Drake (UnrevisedLemkeSolver, MobyLcpSolver),
and writes a Markdown table into BENCHMARKS.md between the markers
``<!-- lcp-peers:begin -->`` and ``<!-- lcp-peers:end -->``.

Examples::

    python benches/peer_lcp.py --quick --output /tmp/bench.md
    python benches/peer_lcp.py --sizes 10,30,100,300,1000
"""

from __future__ import annotations

import argparse
import datetime as dt
import gc
import importlib.metadata
import os
import platform
import shlex
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

# Timings are single-threaded: numpy's BLAS worker threads (left polling after the problem
# generators' matrix products) would otherwise compete for the machine's cores with whichever
# solver is being timed. Set before numpy is imported; applies to every solver alike.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import lcp_problems as lp  # noqa: E402
from markers import write_block  # noqa: E402

REPO_ROOT = Path(__file__).resolve().parents[1]
ERROR_OK = 1e-8
REFERENCE = "coulomb"  # the solver whose time the speed-up ratios divide by
DEFAULT_SIZES = (10, 30, 100, 300, 1000)
QUICK_SIZES = (10, 30)
DEFAULT_SICONOS = REPO_ROOT.parent / "shared/data/siconos-lcp/lcp_tobenna.dat"
# Skip a solver at a larger n when a cubic extrapolation of its last time
# exceeds this many times the per-solve limit (avoids one multi-minute solve).
EXTRAPOLATION_SLACK = 4.0


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------
# Solver adapters: load() -> prepare(M, q) -> call() -> Outcome
# --------------------------------------------------------------------------


@dataclass
class Outcome:
    """What one solve returned, normalised across solvers."""

    z: np.ndarray | None
    success: bool
    pivots: int | None
    status: str
    reported_error: float | None = None
    internal_time: float | None = None  # the solver's own timing, if it reports one


Call = Callable[[], Outcome]
Prepare = Callable[[np.ndarray, np.ndarray], Call]


@dataclass
class SolverSpec:
    """A named solver; ``load(notes)`` imports it (may raise) and returns a preparer."""

    name: str
    load: Callable[[list[str]], Prepare]
    description: str
    notes: list[str] = field(default_factory=list)


def load_coulomb(notes: list[str]) -> Prepare:
    import coulomb.lcp

    def prepare(m: np.ndarray, q: np.ndarray) -> Call:
        def call() -> Outcome:
            res = coulomb.lcp.solve(m, q, method="lemke")
            return Outcome(
                np.asarray(res.z, dtype=np.float64),
                bool(res.success),
                None if res.pivots is None else int(res.pivots),
                str(res.status),
                None if res.error is None else float(res.error),
                getattr(res, "solve_time", None),
            )

        return call

    return prepare


def load_quantecon(notes: list[str]) -> Prepare:
    from quantecon.optimize import lcp_lemke

    warm = lp.small_3x3(seed=12345)
    start = time.perf_counter()
    lcp_lemke(warm.M, warm.q)  # numba JIT compile, excluded from all timings
    notes.append(f"numba JIT warm-up call {time.perf_counter() - start:.2f} s, excluded")

    def prepare(m: np.ndarray, q: np.ndarray) -> Call:
        def call() -> Outcome:
            res = lcp_lemke(m, q)
            return Outcome(res.z, bool(res.success), int(res.num_iter), f"status={res.status}")

        return call

    return prepare


def lemkelcp_max_iter(n: int) -> int:
    """Pivot cap passed to lemkelcp (its default of 100 is too small for n >= 100)."""
    return max(100, 20 * n)


def _list_range(*args: int) -> list[int]:
    return list(range(*args))


def load_lemkelcp(notes: list[str]) -> Prepare:
    import lemkelcp.lemkelcp as module
    from lemkelcp.lemkelcp import lemkelcp

    probe = lp.small_3x3(seed=12345)
    try:
        lemkelcp(probe.M, probe.q, 100)
    except TypeError as exc:
        # lemkelcp 0.1 is Python 2 code: it assigns into range(n) objects.
        module.range = _list_range
        lemkelcp(probe.M, probe.q, 100)
        notes.append(
            f"Python-2 code (`{exc}`): run with its module-level `range` "
            "replaced by `list(range(...))`"
        )

    def prepare(m: np.ndarray, q: np.ndarray) -> Call:
        max_iter = lemkelcp_max_iter(q.shape[0])

        def call() -> Outcome:
            z, exit_code, message = lemkelcp(m, q, max_iter)
            z_out = None if z is None else np.asarray(z, dtype=np.float64)
            return Outcome(z_out, exit_code == 0, None, str(message))

        return call

    return prepare


def load_drake(solver_class: str, fresh: bool) -> Prepare:
    """Drake via ``MathematicalProgram.AddLinearComplementarityConstraint``.

    ``fresh``: every timed call builds the program and the solver (the way a
    user calls it once). Otherwise the program is built once and each timed
    call constructs the solver, runs ``Solve`` and reads the solution. A new
    solver object per call is needed for a cold solve: ``UnrevisedLemkeSolver``
    retries the previous call's basis when n is unchanged (a warm start).
    """
    from pydrake import solvers

    cls = getattr(solvers, solver_class)

    def build(m: np.ndarray, q: np.ndarray) -> tuple[object, object]:
        prog = solvers.MathematicalProgram()
        z = prog.NewContinuousVariables(q.shape[0], "z")
        prog.AddLinearComplementarityConstraint(m, q, z)
        return prog, z

    def solve(prog: object, z: object) -> Outcome:
        result = cls().Solve(prog)
        success = result.is_success()
        status = str(result.get_solution_result()).removeprefix("SolutionResult.")
        z_out = np.asarray(result.GetSolution(z)) if success else None
        return Outcome(z_out, success, None, status)

    def prepare(m: np.ndarray, q: np.ndarray) -> Call:
        if fresh:
            return lambda: solve(*build(m, q))
        built = build(m, q)
        return lambda: solve(*built)

    return prepare


def solver_specs() -> list[SolverSpec]:
    specs = [
        SolverSpec(
            REFERENCE,
            load_coulomb,
            '`coulomb.lcp.solve(M, q, method="lemke")`; pivots = `.pivots`',
        ),
        SolverSpec(
            "quantecon",
            load_quantecon,
            "`quantecon.optimize.lcp_lemke(M, q)` (numba, lexicographic Lemke); "
            "pivots = `.num_iter`",
        ),
        SolverSpec(
            "lemkelcp",
            load_lemkelcp,
            "`lemkelcp.lemkelcp.lemkelcp(M, q, maxIter=max(100, 20 n))` (pure Python "
            "tableau, no lexicographic tie-breaking); "
            "no pivot count is returned",
        ),
    ]
    for cls, label in (
        ("UnrevisedLemkeSolver", "drake Lemke"),
        ("MobyLcpSolver", "drake Moby"),
    ):
        specs.append(
            SolverSpec(
                f"{label} (fresh)",
                lambda notes, cls=cls: load_drake(cls, fresh=True),
                f"`pydrake.solvers.{cls}().Solve(prog)` on a new `MathematicalProgram` with "
                "`AddLinearComplementarityConstraint(M, q, z)`; timed: program + solver "
                "construction + `Solve` + `GetSolution`",
            )
        )
        specs.append(
            SolverSpec(
                f"{label} (solve only)",
                lambda notes, cls=cls: load_drake(cls, fresh=False),
                f"same, program built once; timed: `{cls}()` + `Solve` + `GetSolution`",
            )
        )
    return specs


# --------------------------------------------------------------------------
# Timing
# --------------------------------------------------------------------------


@dataclass
class TimingPolicy:
    min_runs: int = 5
    min_time: float = 0.5
    max_time: float = 10.0
    timeout: float = 20.0


@dataclass
class Timing:
    median: float
    runs: int
    warmup: float
    internal_median: float | None = None


def measure(call: Call, policy: TimingPolicy) -> tuple[Outcome, Timing]:
    """Warm up once (untimed in the median), then repeat until stable enough.

    Stops after ``min_runs`` runs and ``min_time`` seconds, or after
    ``max_time`` seconds with at least one run. If the warm-up alone exceeds
    the per-solve limit no further runs are made and its time is reported.
    """
    gc.collect()
    start = time.perf_counter()
    outcome = call()
    warmup = time.perf_counter() - start
    if warmup > policy.timeout:
        return outcome, Timing(warmup, 0, warmup)
    samples: list[float] = []
    internal: list[float] = []
    total = 0.0
    while True:
        start = time.perf_counter()
        repeat = call()
        elapsed = time.perf_counter() - start
        samples.append(elapsed)
        if repeat.internal_time is not None:
            internal.append(repeat.internal_time)
        total += elapsed
        enough = len(samples) >= policy.min_runs and total >= policy.min_time
        if enough or total >= policy.max_time:
            break
    internal_median = statistics.median(internal) if internal else None
    return outcome, Timing(statistics.median(samples), len(samples), warmup, internal_median)


# --------------------------------------------------------------------------
# Running
# --------------------------------------------------------------------------


@dataclass
class Row:
    family: str
    n: int
    solver: str
    timing: Timing | None = None
    outcome: Outcome | None = None
    error: float | None = None
    note: str = ""


@dataclass
class SolverState:
    """Per-solver bookkeeping across problems."""

    spec: SolverSpec
    prepare: Prepare | None = None
    unavailable: str = ""
    exceeded: dict[str, str] = field(default_factory=dict)
    last_time: dict[str, tuple[int, float]] = field(default_factory=dict)


def load_solvers(specs: Iterable[SolverSpec]) -> list[SolverState]:
    states = []
    for spec in specs:
        state = SolverState(spec)
        try:
            state.prepare = spec.load(spec.notes)
            log(f"[load] {spec.name}: ok")
        except Exception as exc:  # any failure means "n/a"
            state.unavailable = f"{type(exc).__name__}: {exc}".splitlines()[0]
            log(f"[load] {spec.name}: n/a ({state.unavailable})")
        states.append(state)
    return states


def skip_reason(state: SolverState, problem: lp.LcpProblem, timeout: float) -> str:
    if state.unavailable:
        return f"n/a: {state.unavailable}"
    if problem.family in state.exceeded:
        return state.exceeded[problem.family]
    previous = state.last_time.get(problem.family)
    if previous is not None:
        n_prev, t_prev = previous
        estimate = t_prev * (problem.n / n_prev) ** 3
        if estimate > EXTRAPOLATION_SLACK * timeout:
            return (
                f"skipped: est. {format_seconds(estimate)}/solve from n={n_prev} "
                f"(limit {timeout:g} s)"
            )
    return ""


def error_mismatch(reported: float | None, recomputed: float | None) -> str:
    """Note when a solver's own error disagrees with the recomputed one."""
    if reported is None or recomputed is None:
        return ""
    if abs(reported - recomputed) <= 1e-12 + 1e-3 * max(reported, recomputed):
        return ""
    return f"solver's own `.error` = {reported:.1e}"


def run_one(state: SolverState, problem: lp.LcpProblem, policy: TimingPolicy) -> Row:
    row = Row(problem.family, problem.n, state.spec.name)
    row.note = skip_reason(state, problem, policy.timeout)
    if row.note:
        return row
    assert state.prepare is not None
    try:
        call = state.prepare(problem.M, problem.q)
        row.outcome, row.timing = measure(call, policy)
    except Exception as exc:  # record and continue
        row.note = f"n/a: raised {type(exc).__name__}: {exc}".splitlines()[0]
        return row
    if row.outcome.z is not None:
        row.error = lp.lcp_error(problem.M, problem.q, row.outcome.z)
    notes = [error_mismatch(row.outcome.reported_error, row.error)]
    if row.timing.internal_median is not None:
        notes.append(f"own `solve_time` median {format_seconds(row.timing.internal_median)}")
    row.note = "; ".join(note for note in notes if note)
    state.last_time[problem.family] = (problem.n, row.timing.median)
    if row.timing.median > policy.timeout:
        took = f"one solve took {format_seconds(row.timing.median)} > limit {policy.timeout:g} s"
        row.note = "; ".join(part for part in (row.note, took) if part)
        reason = f"skipped: exceeded {policy.timeout:g} s/solve at n={problem.n}"
        state.exceeded[problem.family] = reason
    return row


def build_problems(
    sizes: Sequence[int], siconos: Path | None
) -> tuple[list[lp.LcpProblem], list[str]]:
    problems = [lp.dense_spd(n, seed=n) for n in sizes]
    problems += [lp.contact_psd(n, seed=n) for n in sizes]
    problems.append(lp.small_3x3(seed=3))
    notes: list[str] = []
    if siconos is not None:
        try:
            problems.append(lp.siconos_problem(siconos))
        except Exception as exc:  # optional row
            notes.append(f"Siconos `{siconos.name}` row skipped: {type(exc).__name__}: {exc}")
    return problems, notes


def run_all(
    problems: Sequence[lp.LcpProblem],
    states: Sequence[SolverState],
    policy: TimingPolicy,
) -> list[Row]:
    rows = []
    for problem in problems:
        for state in states:
            log(f"[run] {problem.family} n={problem.n} {state.spec.name} ...")
            row = run_one(state, problem, policy)
            log(f"      -> {describe(row)}")
            rows.append(row)
    return rows


def describe(row: Row) -> str:
    if row.timing is None:
        return row.note
    ok = row.outcome.success if row.outcome else False
    err = "n/a" if row.error is None else f"{row.error:.1e}"
    return f"{format_seconds(row.timing.median)} x{row.timing.runs}, success={ok}, error={err}"


# --------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------


def format_seconds(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds:.2f} s"


def solved(row: Row) -> bool:
    """The solver claimed success and the recomputed error agrees."""
    ok = row.outcome is not None and row.outcome.success
    return ok and row.error is not None and row.error <= ERROR_OK


def speedup(row: Row, reference: Row | None) -> str:
    if reference is None or reference.timing is None or row.timing is None:
        return "n/a"
    if row is reference:
        return "(ref)"
    ratio = f"{row.timing.median / reference.timing.median:.1f}x"
    if not solved(reference):
        return f"({ratio}, coulomb failed)"
    if not solved(row):
        return f"({ratio}, peer failed)"
    return ratio


def table_row(row: Row, reference: Row | None) -> str:
    if row.timing is None:
        cells = [str(row.n), row.solver, "—", "—", "—", "—", "—", "—", "—", row.note]
        return "| " + " | ".join(cells) + " |"
    out = row.outcome
    assert out is not None
    runs = "1 (warm-up)" if row.timing.runs == 0 else str(row.timing.runs)
    pivots = "n/a" if out.pivots is None else str(out.pivots)
    error = "n/a (no z)" if row.error is None else f"{row.error:.1e}"
    success = "yes" if out.success else f"no ({out.status})"
    error_ok = "n/a" if row.error is None else ("yes" if row.error <= ERROR_OK else "**NO**")
    cells = [
        str(row.n),
        row.solver,
        format_seconds(row.timing.median),
        runs,
        pivots,
        error,
        success,
        error_ok,
        speedup(row, reference),
        row.note,
    ]
    return "| " + " | ".join(cells) + " |"


TABLE_HEADER = (
    "| n | solver | median time / solve | runs | pivots | error | success | "
    "error ok (<=1e-8) | coulomb speed-up | note |\n"
    "|---:|---|---:|---:|---:|---:|---|---|---:|---|"
)


def family_tables(rows: Sequence[Row], problems: Sequence[lp.LcpProblem]) -> list[str]:
    lines: list[str] = []
    families = list(dict.fromkeys(p.family for p in problems))
    labels = {(p.family, p.n): p.label for p in problems}
    for family in families:
        lines += [
            "",
            f"### {family}",
            "",
            FAMILY_TEXT.get(family, ""),
            "",
            TABLE_HEADER,
        ]
        family_rows = [r for r in rows if r.family == family]
        for n in dict.fromkeys(r.n for r in family_rows):
            group = [r for r in family_rows if r.n == n]
            reference = next((r for r in group if r.solver == REFERENCE and r.timing), None)
            lines += [table_row(r, reference) for r in group]
        instances = ", ".join(f"n={n}: {lab}" for (f, n), lab in labels.items() if f == family)
        lines += ["", f"Instances: {instances}."]
    return lines


FAMILY_TEXT = {
    lp.FAMILY_DENSE_SPD: "`M = A A^T / n + I` (A standard normal), `q` standard normal.",
    lp.FAMILY_CONTACT_PSD: (
        "`M = J J^T`, `J` of shape n x n/2 (rank-deficient, like redundant contacts); "
        "planted `z* >= 0` on a random half of the indices, `w* > 0` on the rest, "
        "`q = w* - M z*`."
    ),
    lp.FAMILY_SMALL_3X3: "A 3x3 dense SPD problem: per-call overhead (times in µs).",
    lp.FAMILY_SICONOS: "Siconos test file read with `coulomb.io.read_siconos_lcp`.",
}


def package_version(name: str) -> str:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def git(*args: str) -> str:
    out = subprocess.run(
        ["git", "-C", str(REPO_ROOT), *args], capture_output=True, text=True, check=True
    )
    return out.stdout.strip()


def git_revision() -> str:
    try:
        revision = git("rev-parse", "--short", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return revision + (" (with uncommitted changes)" if dirty else "")


def machine_lines() -> list[str]:
    versions = ", ".join(
        f"{name} {package_version(name)}"
        for name in ("coulomb", "numpy", "numba", "quantecon", "lemkelcp", "drake")
    )
    affinity = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return [
        f"- CPU: {cpu_model()}; {os.cpu_count()} logical cores ({affinity} usable)",
        f"- OS: {platform.system()} {platform.release()}; Python {platform.python_version()}",
        f"- Packages: {versions}",
        f"- Repository revision: {git_revision()}",
    ]


def method_text(policy: TimingPolicy) -> str:
    return (
        "Method: all solvers run in one process on the same `(M, q)`. One warm-up call "
        "per case is excluded; then the solve is repeated until at least "
        f"{policy.min_runs} runs and {policy.min_time:g} s (or {policy.max_time:g} s in "
        "total) and the median `time.perf_counter` wall time is reported. "
        "BLAS and OpenMP thread pools are limited to one thread "
        f"(`OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}`), so no idle "
        "worker competes with the solver being timed. "
        "`error = ||min(z, M z + q)||_2 / max(1, ||q||_2)` is recomputed here from the "
        "original `M, q` for every solver; `success` is the solver's own claim. "
        "`coulomb speed-up` = peer median / coulomb median (>1 means coulomb is faster); "
        "it is put in parentheses when either side did not solve the problem. "
        f"A solver is skipped at larger n once one solve exceeds {policy.timeout:g} s."
    )


def render_section(
    rows: Sequence[Row],
    problems: Sequence[lp.LcpProblem],
    states: Sequence[SolverState],
    policy: TimingPolicy,
    command: str,
    extra_notes: Sequence[str],
    quick: bool,
) -> str:
    now = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    title = "## LCP solvers: coulomb vs peers" + (" (quick smoke run)" if quick else "")
    lines = [
        title,
        "",
        f"Generated by `benches/peer_lcp.py` on {now}. Command:",
        "",
        "```",
        command,
        "```",
        "",
        *machine_lines(),
        "",
        method_text(policy),
        *family_tables(rows, problems),
        "",
        "### Solvers and notes",
        "",
    ]
    for state in states:
        extra = "; ".join(state.spec.notes)
        status = f" — **n/a**: {state.unavailable}" if state.unavailable else ""
        lines.append(
            f"- **{state.spec.name}**: {state.spec.description}"
            + (f" ({extra})" if extra else "")
            + status
        )
    lines += [f"- {note}" for note in (*DRAKE_NOTES, *extra_notes)]
    return "\n".join(lines)


DRAKE_NOTES = (
    (
        "Drake: pydrake binds only the constructor and `id()` of `UnrevisedLemkeSolver` and "
        "`MobyLcpSolver`, and `MathematicalProgramResult.get_solver_details()` is not set for "
        "them, so no pivot count is available from Python."
    ),
    (
        "Drake `MobyLcpSolver` called through `MathematicalProgram` runs (per Drake's source) "
        "`SolveLcpLemkeRegularized` (retries on `M + λI` for growing λ), so its `z` may solve "
        "a regularized problem: see the error column."
    ),
    (
        "Drake `UnrevisedLemkeSolver` keeps the last basis in the solver object and, for the "
        "same n, first tries it (a warm start: re-solving the same problem costs one linear "
        "solve). Every timed Drake call here uses a new solver object, so all rows are cold "
        "solves."
    ),
)


def write_section(section: str, output: Path) -> None:
    """Replace the marked section in ``output`` (create the file if needed)."""
    write_block("lcp-peers", section, output)


# --------------------------------------------------------------------------
# CLI
# --------------------------------------------------------------------------


def parse_sizes(text: str) -> tuple[int, ...]:
    sizes = tuple(int(part) for part in text.split(",") if part.strip())
    if not sizes or min(sizes) < 1:
        raise argparse.ArgumentTypeError("sizes must be positive integers, e.g. 10,30,100")
    return sizes


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sizes",
        type=parse_sizes,
        default=DEFAULT_SIZES,
        help="comma-separated n for the dense and contact families (default: 10,30,100,300,1000)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="smoke run: sizes 10,30 and a shorter minimum time per case",
    )
    parser.add_argument(
        "--output",
        type=Path,
        default=REPO_ROOT / "BENCHMARKS.md",
        help="Markdown file whose lcp-peers section is (re)written; '-' for stdout",
    )
    parser.add_argument(
        "--timeout-per-solve",
        type=float,
        default=20.0,
        help="skip a solver at larger n once one solve exceeds this (s)",
    )
    parser.add_argument("--min-runs", type=int, default=5)
    parser.add_argument(
        "--min-time", type=float, default=0.5, help="minimum timed seconds per case"
    )
    parser.add_argument(
        "--max-time",
        type=float,
        default=10.0,
        help="stop repeating a case after this many seconds",
    )
    parser.add_argument(
        "--siconos",
        type=Path,
        default=DEFAULT_SICONOS,
        help="Siconos .dat file for the extra row (needs coulomb)",
    )
    parser.add_argument(
        "--solvers",
        default="",
        help="comma-separated subset of solver names (default: all)",
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.sizes = QUICK_SIZES if args.sizes == DEFAULT_SIZES else args.sizes
        args.min_time = min(args.min_time, 0.1)
    return args


def select_specs(names: str) -> list[SolverSpec]:
    specs = solver_specs()
    wanted = [name.strip() for name in names.split(",") if name.strip()]
    if not wanted:
        return specs
    chosen = [s for s in specs if s.name in wanted or s.name.split(" (")[0] in wanted]
    if not chosen:
        raise SystemExit(f"no solver matches {wanted}; known: {[s.name for s in specs]}")
    return chosen


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    command = shlex.join([Path(sys.executable).name, *(sys.argv if argv is None else argv)])
    policy = TimingPolicy(args.min_runs, args.min_time, args.max_time, args.timeout_per_solve)
    states = load_solvers(select_specs(args.solvers))
    problems, notes = build_problems(args.sizes, args.siconos)
    rows = run_all(problems, states, policy)
    section = render_section(rows, problems, states, policy, command, notes, args.quick)
    if str(args.output) == "-":
        print(section)
    else:
        write_section(section, args.output)
        log(f"[done] wrote {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
