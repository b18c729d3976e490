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
below, which live in ``coulomb._presets`` and are re-exported here). Each point is timed inside
its worker.
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
from typing import Any

import numpy as np

from . import _validate
from ._extras import require
from ._presets import (
    PRESETS,
    contact_tolerance,
    floor_impact,
    nsgs_tolerance,
    painleve_jam,
    ramp,
    regularized_ramp,
)
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
