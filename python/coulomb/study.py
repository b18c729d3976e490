"""Measure the trade between speed and accuracy: sweep the settings a user turns.

A *study* runs one scene or solve at every point of a grid of settings (step size, solver,
facets, tolerance, iteration limit, ...), measures each point's error against a reference
(an analytic answer where one exists, else a run at much finer settings) and its cost (wall
time, plus whatever the run reports: iterations, pivots, function evaluations), and returns
the records, their Pareto front and fitted convergence orders.

>>> from coulomb import study
>>> s = study.sweep(study.regularized_ramp, {"eps": [1e-1, 1e-2, 1e-3]},
...                 reference={"creep": 0.0})                      # doctest: +SKIP
>>> s.pareto()                                                      # doctest: +SKIP

Runs are independent, so ``executor`` may be any :class:`concurrent.futures.Executor`: a local
``ProcessPoolExecutor``, or a Dask or Ray cluster's (``client.get_executor()``). The run
function must then be importable by the workers (a module-level function, such as the presets
here). Each point is timed inside its worker.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any, Literal

import numpy as np

from . import _validate
from ._extras import require
from .errors import ArgumentTypeError, InvalidParameterError

__all__ = [
    "Study",
    "contact_tolerance",
    "convergence_order",
    "floor_impact",
    "nsgs_tolerance",
    "painleve_jam",
    "pareto_front",
    "ramp",
    "regularized_ramp",
    "sweep",
]

Record = dict[str, Any]
Run = Callable[..., Mapping[str, Any]]


def _grid_points(grid: Mapping[str, Sequence[Any]] | Iterable[Mapping[str, Any]]) -> list[Record]:
    if isinstance(grid, Mapping):
        for key, values in grid.items():
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                raise InvalidParameterError(
                    f"grid[{key!r}] must be a sequence of values, got {values!r}"
                )
        keys = list(grid)
        return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*grid.values())]
    points = [dict(p) for p in grid]
    for p in points:
        if not isinstance(p, dict):
            raise InvalidParameterError("grid must be a mapping of sequences or of settings dicts")
    return points


def _timed_call(run: Run, settings: Mapping[str, Any], repeat: int) -> tuple[Record, float]:
    """Runs one point ``repeat`` times in the worker; the best wall time is its cost."""
    best = math.inf
    out: Mapping[str, Any] = {}
    for _ in range(repeat):
        start = time.perf_counter()
        out = run(**settings)
        best = min(best, time.perf_counter() - start)
    return dict(out), best


def _errors(out: Mapping[str, Any], reference: Mapping[str, float]) -> Record:
    """|value - reference| per named quantity, its relative form, and ``error``: the worst
    relative error (absolute where the reference is 0)."""
    rec: Record = {}
    worst = 0.0
    for key, ref in reference.items():
        if key not in out:
            raise InvalidParameterError(
                f"the run returned no {key!r} to compare with the reference (it returned "
                f"{sorted(out)})"
            )
        value = float(out[key])
        err = abs(value - float(ref))
        rel = err / abs(ref) if ref != 0 else err
        rec[f"error_{key}"] = err
        rec[f"rel_error_{key}"] = rel
        worst = max(worst, rel) if math.isfinite(rel) else math.inf
    rec["error"] = worst
    return rec


def pareto_front(
    records: Sequence[Record], error: str = "error", cost: str = "time"
) -> list[Record]:
    """The records no other record beats on both ``error`` and ``cost`` (smaller is better),
    sorted by cost. Records with a non-finite error are never on the front."""
    pts = [r for r in records if math.isfinite(float(r[error])) and math.isfinite(float(r[cost]))]
    pts.sort(key=lambda r: (float(r[cost]), float(r[error])))
    front: list[Record] = []
    best = math.inf
    for r in pts:
        if float(r[error]) < best:
            front.append(r)
            best = float(r[error])
    return front


def convergence_order(x: Sequence[float], error: Sequence[float]) -> float:
    """The slope p of ``log(error) = p log(x) + c`` by least squares: the measured order.

    Points with a zero or non-finite error are left out (they carry no slope); at least two
    must remain.
    """
    xs = np.asarray(x, dtype=float)
    es = np.asarray(error, dtype=float)
    keep = np.isfinite(xs) & np.isfinite(es) & (xs > 0) & (es > 0)
    if keep.sum() < 2:
        raise InvalidParameterError("need at least two points with a positive, finite error")
    slope, _ = np.polyfit(np.log(xs[keep]), np.log(es[keep]), 1)
    return float(slope)


class Study:
    """The records of a sweep, with their front, orders, exports and plot.

    ``records`` holds one dict per point: the settings, what the run returned, ``time`` (best
    wall time in seconds) and, when a reference was given, ``error`` and per-quantity
    ``error_<name>`` / ``rel_error_<name>``.
    """

    def __init__(
        self,
        records: list[Record],
        settings: list[str],
        reference: Mapping[str, float] | None,
        name: str = "study",
    ) -> None:
        self.records = records
        self.settings = settings
        self.reference = dict(reference) if reference is not None else None
        self.name = name

    def __len__(self) -> int:
        return len(self.records)

    def __repr__(self) -> str:
        lines = [f"Study({self.name!r}: {len(self.records)} points over {self.settings})"]
        if self.reference is not None:
            front = self.pareto()
            lines.append(f"  Pareto front ({len(front)} points, error against time):")
            for r in front:
                s = ", ".join(f"{k}={r[k]!r}" for k in self.settings)
                lines.append(f"    {s}: error {r['error']:.3g}, time {r['time']:.3g} s")
        return "\n".join(lines)

    def pareto(self, error: str = "error", cost: str = "time") -> list[Record]:
        """See :func:`pareto_front`."""
        return pareto_front(self.records, error, cost)

    def order(self, setting: str, error: str = "error", where: Mapping[str, Any] | None = None):
        """The convergence order in one setting (see :func:`convergence_order`), over the
        records whose other settings match ``where``."""
        rows = [r for r in self.records if all(r.get(k) == v for k, v in (where or {}).items())]
        return convergence_order([r[setting] for r in rows], [r[error] for r in rows])

    def columns(self) -> list[str]:
        cols: list[str] = []
        for r in self.records:
            for k in r:
                if k not in cols:
                    cols.append(k)
        return cols

    def to_csv(self, path: str | Path) -> Path:
        path = Path(path)
        cols = self.columns()
        with path.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=cols)
            w.writeheader()
            for r in self.records:
                w.writerow({k: r.get(k, "") for k in cols})
        return path

    def to_json(self, path: str | Path | None = None) -> str:
        def clean(v: Any) -> Any:
            if isinstance(v, (np.floating, np.integer)):
                return v.item()
            if isinstance(v, float) and not math.isfinite(v):
                return str(v)
            return v

        text = json.dumps(
            {
                "name": self.name,
                "settings": self.settings,
                "reference": self.reference,
                "records": [{k: clean(v) for k, v in r.items()} for r in self.records],
            },
            indent=1,
        )
        if path is not None:
            Path(path).write_text(text)
        return text

    def plot(
        self, x: str = "time", y: str = "error", ax: Any = None, path: str | Path | None = None
    ):
        """Error against cost on log axes, the Pareto front joined (needs matplotlib, the
        ``plot`` extra)."""
        require("matplotlib", extra="plot", what="Study.plot")
        import matplotlib

        if ax is None and path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        from ._plot import place_labels, study_axis_label

        xs = [float(r[x]) for r in self.records]
        ys = [float(r[y]) for r in self.records]
        ax.scatter(xs, ys, s=14, alpha=0.6, label="settings")
        front = pareto_front(self.records, y, x)
        ax.plot([r[x] for r in front], [r[y] for r in front], "r.-", label="Pareto front")
        if all(v > 0 for v in xs):
            ax.set_xscale("log")
        if all(v > 0 for v in ys):
            ax.set_yscale("log")
        # the front's points numbered beside them (kept apart), their settings in the legend
        place_labels(ax, [(float(r[x]), float(r[y])) for r in front],
                     [str(i + 1) for i in range(len(front))])
        for i, r in enumerate(front):
            ax.plot([], [], " ", label=f"{i + 1}: " + ", ".join(
                f"{k}={r[k]}" for k in self.settings))
        ax.set_xlabel(study_axis_label(x))
        ax.set_ylabel(study_axis_label(y))
        ax.set_title(self.name)
        ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
        if path is not None:
            ax.figure.savefig(path, dpi=120, bbox_inches="tight")
        return ax


def sweep(
    run: Run,
    grid: Mapping[str, Sequence[Any]] | Iterable[Mapping[str, Any]],
    *,
    reference: Mapping[str, float] | None = None,
    reference_settings: Mapping[str, Any] | None = None,
    quantities: Sequence[str] | None = None,
    executor: Executor | None = None,
    repeat: int = 1,
    progress: bool | Callable[[str], None] = False,
    name: str | None = None,
) -> Study:
    """Run ``run(**settings)`` at every grid point and measure error and cost.

    Parameters
    ----------
    run
        Returns a mapping of measured quantities (and any cost counters, e.g. iterations).
    grid
        ``{"h": [...], "solver": [...]}`` (every combination) or a list of settings dicts.
    reference
        The exact value of some returned quantities. Or give ``reference_settings``: the
        reference is then the run at those (much finer) settings, made first.
    quantities
        Which returned quantities the error compares (default: every one the reference has).
    executor
        Where the points run (default: here, one after the other).
    repeat
        Runs per point; the best wall time is kept (the outputs must not change).
    progress
        True prints one line per finished point to stderr; or a callable taking the line.
    """
    if not callable(run):
        raise ArgumentTypeError(f"run must be a callable returning a mapping, got {run!r}")
    repeat = _validate.count("repeat", repeat)
    if reference is not None and reference_settings is not None:
        raise InvalidParameterError("give reference or reference_settings, not both")
    points = _grid_points(grid)
    if not points:
        raise InvalidParameterError("the grid is empty")
    say: Callable[[str], None] | None
    if progress is True:
        say = lambda line: print(line, file=sys.stderr, flush=True)  # noqa: E731
    elif callable(progress):
        say = progress
    else:
        say = None
    if reference_settings is not None:
        ref_out, _ = _timed_call(run, reference_settings, 1)
        reference = {
            k: float(v)
            for k, v in ref_out.items()
            if isinstance(v, (int, float)) and not isinstance(v, bool)
        }
        if say:
            say(f"reference at {dict(reference_settings)}: {reference}")
    if reference is not None and quantities is not None:
        missing = [k for k in quantities if k not in reference]
        if missing:
            raise InvalidParameterError(f"no reference value for {missing}")
        reference = {k: reference[k] for k in quantities}
    settings_keys: list[str] = []
    for p in points:
        for k in p:
            if k not in settings_keys:
                settings_keys.append(k)
    results: list[tuple[Record, float] | None] = [None] * len(points)
    total = len(points)

    def done(i: int, value: tuple[Record, float], count: int) -> None:
        results[i] = value
        if say:
            _out, seconds = value
            text = ", ".join(f"{k}={v!r}" for k, v in points[i].items())
            say(f"[{count}/{total}] {text}: {seconds:.3g} s")

    if executor is None:
        for i, p in enumerate(points):
            done(i, _timed_call(run, p, repeat), i + 1)
    else:
        from concurrent.futures import as_completed

        futures = {executor.submit(_timed_call, run, p, repeat): i for i, p in enumerate(points)}
        for count, fut in enumerate(as_completed(futures), start=1):
            done(futures[fut], fut.result(), count)
    records: list[Record] = []
    for p, res in zip(points, results, strict=True):
        assert res is not None
        out, seconds = res
        rec: Record = {**p, **out, "time": seconds}
        if reference is not None:
            rec.update(_errors(out, reference))
        records.append(rec)
    return Study(records, settings_keys, reference, name or str(getattr(run, "__name__", "study")))


# ---- presets: runs importable by any worker -------------------------------------------------


def regularized_ramp(
    eps: float = 1e-3,
    method: str = "Radau",
    rtol: float = 1e-8,
    theta_deg: float = 20.0,
    mu: float = 0.4,
    v0: float = 1.0,
    t_end: float = 10.0,
) -> dict[str, float]:
    """The chapter's ramp under the tanh-smoothed law: ``creep`` is how far past the exact Coulomb
    stop (1.505 m) the block has gone at ``t_end``; ``nfev`` the ODE solver's cost."""
    from .regularized import coulomb_ramp, simulate_ramp

    theta = math.radians(theta_deg)
    res = simulate_ramp(theta, mu, v0, t_end, eps, method=method, rtol=rtol, atol=rtol * 1e-2)
    s_exact, _ = coulomb_ramp(theta, mu, v0, np.array([t_end]))
    return {"creep": float(res.s[-1] - s_exact[0]), "nfev": res.nfev, "njev": res.njev}


def contact_tolerance(
    tol: float = 1e-8, method: Literal["nsgs", "lemke", "prox"] = "nsgs", facets: int = 8
) -> dict[str, float]:
    """The chapter's oblique inelastic impact in 3D (m = 2, v = (-3, 1, 0), mu = 0.2) with slip
    at 30 deg off the first tangent, solved at tolerance ``tol``: returns the post-step slip
    speed ``u_t`` (exactly 0.4) and the solver's work."""
    from . import contact

    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    options: dict[str, Any] = {"tol": tol}
    if method == "lemke":
        options["facets"] = facets
    r = contact.solve(np.eye(3) / 2.0, [-3.0, c, s], 0.2, dim=3, method=method, **options)
    u = r.velocity[0]
    return {
        "u_t": float(math.hypot(u[1], u[2])),
        "u_n": float(u[0]),
        "iterations": int(r.get("iterations", r.get("pivots", 0)) or 0),
        "success": bool(r.success),
    }


def _stack_problem(nc: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A reproducible 3D contact problem: W = J M^-1 J^T for nc contacts on a chain of bodies
    (each contact couples two neighbouring bodies, like a stack), q pushing them together
    with some slip."""
    rng = np.random.default_rng(seed)
    nb = nc + 1
    J = np.zeros((3 * nc, 6 * nb))
    for i in range(nc):
        frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        arm = rng.normal(scale=0.1, size=3)
        for body, sign in ((i, 1.0), (i + 1, -1.0)):
            lin = sign * frame.T
            ang = (
                sign
                * frame.T
                @ np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]]).T
            )
            J[3 * i : 3 * i + 3, 6 * body : 6 * body + 3] = lin
            J[3 * i : 3 * i + 3, 6 * body + 3 : 6 * body + 6] = ang
    minv = np.diag(np.tile([1.0, 1.0, 1.0, 6.0, 6.0, 6.0], nb))
    W = J @ minv @ J.T
    q = rng.normal(size=3 * nc)
    q[0::3] = -np.abs(q[0::3]) - 0.5
    return W, q


def nsgs_tolerance(
    tol: float = 1e-8, nc: int = 12, seed: int = 1, mu: float = 0.5
) -> dict[str, Any]:
    """A chain of ``nc`` frictional contacts (see ``_stack_problem``) solved by NSGS at ``tol``:
    returns the total normal impulse and total slip speed (compare with a run at tol 1e-14)
    and the sweeps it took."""
    from . import contact

    W, q = _stack_problem(nc, seed)
    r = contact.solve(W, q, mu, dim=3, method="nsgs", tol=tol, max_iter=100_000)
    u = r.velocity
    return {
        "normal_impulse": float(r.impulse[:, 0].sum()),
        "slip": float(np.hypot(u[:, 1], u[:, 2]).sum()),
        "iterations": int(r.iterations),
        "solver_error": float(r.error),
    }


def ramp(
    h: float = 1e-3,
    solver: Literal["nsgs", "lemke"] = "nsgs",
    tol: float | None = None,
    facets: int | None = None,
    warm_start: bool = True,
    max_iter: int | None = None,
    drift: str = "none",
    t_end: float = 4.0,
) -> dict[str, Any]:
    """The chapter's ramp (20 deg, mu = 0.4, v0 = 1 m/s down the slope) stepped at ``h``:
    ``stop_distance`` (exact 1.5053 m), ``stop_time`` (exact 3.0112 s), ``creep`` (motion after
    the stop; exact 0) and the stepper's work. Every setting a user trades is an argument:
    step, solver, tolerance, facets, warm start, iteration limit, drift correction."""
    from .model import HalfSpace, Particle, Point, Scene

    th = math.radians(20.0)
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    block = scene.add(
        Particle(mass=1.0, position=(0.0, 0.0), velocity=(math.cos(th), -math.sin(th)))
    )
    scene.contact(scene.attach(block, Point()), scene.add(HalfSpace.ramp(20.0)), mu=0.4)
    tr = scene.simulate(
        t_end,
        h,
        solver,
        tol=tol,
        facets=facets,
        warm_start=warm_start,
        max_iter=max_iter,
        drift=drift,  # type: ignore[arg-type]
    )
    still = np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))
    k = int(still[0]) if len(still) else len(tr.t) - 1
    s = tr.q[:, 0] * math.cos(th) - tr.q[:, 1] * math.sin(th)
    return {
        "stop_distance": float(s[k]),
        "stop_time": float(tr.t[k]),
        "creep": float(abs(s[-1] - s[k])),
        "iterations": int(np.sum(tr.iterations)),
        "success": bool(tr.success),
    }


def painleve_jam(h: float = 1e-3, solver: str = "nsgs") -> dict[str, Any]:
    """The chapter's Painleve rod (m = 1, l = 1, J = 1/12, mu = 2, 45 deg, end sliding left at
    1 m/s): the first step's impulse, which jams the end. Its limit as h -> 0 stops the end
    exactly: ``P_n = 0.375``, ``P_t = 0.625`` N s."""
    from .model import HalfSpace, RigidBody2D, Scene, Segment

    th = math.radians(45.0)
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    rod = scene.add(
        RigidBody2D(
            mass=1.0,
            inertia=1.0 / 12.0,
            position=(0.0, 0.5 * math.sin(th)),
            angle=th,
            velocity=(-1.0, 0.0),
        )
    )
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    tr = scene.simulate(3 * h, h, solver)  # type: ignore[arg-type]
    first = tr.contact_step == 0
    pn, pt = tr.contact_impulse[first][0]
    return {"P_n": float(pn), "P_t": float(pt), "success": bool(tr.success)}


def floor_impact(h: float = 1e-3, phase: float = 0.3, speed: float = 3.0) -> dict[str, Any]:
    """The chapter's floor impact (m = 0.5 kg, e = 0.6) at ``speed`` m/s, the impact falling
    ``phase`` of the way into a step: the rebound (exact: ``0.6 speed``) and impulse (exact:
    ``0.8 speed`` N s)."""
    from .model import HalfSpace, Particle, Point, Scene

    scene = Scene(dim=2, gravity=(0.0, 0.0))
    ball = scene.add(Particle(mass=0.5, position=(0.0, phase * speed * h), velocity=(0.0, -speed)))
    scene.contact(scene.attach(ball, Point()), scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0))), e=0.6)
    tr = scene.simulate(4 * h, h)
    return {
        "rebound": float(tr.v[-1, 1]),
        "impulse": float(tr.contact_impulse[:, 0].sum()),
        "success": bool(tr.success),
    }


#: Named studies for ``coulomb study NAME``: the run, its grid, its reference, and the
#: setting whose convergence order is reported.
PRESETS: dict[str, dict[str, Any]] = {
    "facets": {
        "run": contact_tolerance,
        # powers of two keep the slip (30 deg) a third of a facet spacing from the nearest
        # direction, so the error measures the spacing alone (12 or 24 facets contain 30 deg
        # and are exact)
        "grid": {"method": ["lemke"], "facets": [4, 8, 16, 32, 64, 128]},
        "reference": {"u_t": 0.4},
        "order": "facets",
        "about": "polyhedral cone on the chapter's oblique impact: slip error against facets",
    },
    "nsgs-tolerance": {
        "run": nsgs_tolerance,
        "grid": {"tol": [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10, 1e-12]},
        "reference_settings": {"tol": 1e-14},
        "quantities": ["normal_impulse"],
        "order": "tol",
        "about": "NSGS on a 12-contact chain: impulse error against tolerance",
    },
    "ramp-h": {
        "run": ramp,
        "grid": {"h": [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], "solver": ["nsgs", "lemke"]},
        "reference": {
            "stop_distance": 1.0
            / (2.0 * 9.81 * (0.4 * math.cos(math.radians(20.0)) - math.sin(math.radians(20.0))))
        },
        "order": "h",
        "order_where": {"solver": "nsgs"},
        "about": "the chapter's ramp: stop-distance error against step size and solver",
    },
    "impact-h": {
        "run": floor_impact,
        "grid": {"h": [1e-1, 1e-2, 1e-3, 1e-4, 1e-5], "phase": [0.0, 0.3, 0.9]},
        "reference": {"rebound": 1.8, "impulse": 2.4},
        "order": "h",
        "about": "the chapter's floor impact (e = 0.6): rebound and impulse against step size and "
        "where in the step the impact falls (exact at every h)",
    },
    "painleve-h": {
        "run": painleve_jam,
        "grid": {"h": [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5]},
        "reference": {"P_n": 0.375, "P_t": 0.625},
        "order": "h",
        "about": "Painleve's rod: the jam impulse against step size (limit 0.375, 0.625 N s)",
    },
    "regularized-ramp": {
        "run": regularized_ramp,
        "grid": {"eps": [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], "method": ["Radau", "RK45"]},
        "reference": {"creep": 0.0},
        "order": "eps",
        "order_where": {"method": "Radau"},
        "about": "tanh-smoothed friction on the chapter's ramp: creep against eps, ODE cost",
        # (module, extra): checked before the study starts
        "needs": [("scipy.integrate", "ode")],
    },
}


def require_preset(name: str) -> None:
    """Raises :class:`coulomb._extras.MissingExtraError` (an ImportError naming the extra) if
    an optional dependency of the named study is not installed."""
    for module, extra in PRESETS[name].get("needs", ()):
        require(module, extra=extra, what=f"the study {name!r}")


def run_preset(
    name: str, executor: Executor | None = None, progress: bool | Callable[[str], None] = False
) -> Study:
    """Runs the named study of :data:`PRESETS`."""
    if name not in PRESETS:
        raise InvalidParameterError(f"unknown study {name!r}: expected one of {sorted(PRESETS)}")
    require_preset(name)
    p = PRESETS[name]
    return sweep(
        p["run"],
        p["grid"],
        reference=p.get("reference"),
        reference_settings=p.get("reference_settings"),
        quantities=p.get("quantities"),
        executor=executor,
        progress=progress,
        name=name,
    )
