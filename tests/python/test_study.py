"""coulomb.study: sweeps, errors against references, Pareto fronts, orders, executors."""

from __future__ import annotations

import itertools
import json
import math
from concurrent.futures import ProcessPoolExecutor

import pytest
from coulomb import study
from coulomb.errors import InvalidParameterError


def _strip_time(records):
    return [{k: v for k, v in r.items() if k != "time"} for r in records]


def test_facets_front_is_monotone_and_second_order() -> None:
    s = study.sweep(
        study.contact_tolerance,
        {"method": ["lemke"], "facets": [4, 8, 16, 32, 64]},
        reference={"u_t": 0.4},
    )
    errors = [r["error"] for r in s.records]
    assert all(a > b for a, b in itertools.pairwise(errors))
    # the polygon's inscribed error falls like 1 - cos(pi / s) ~ s^-2
    assert -2.2 < s.order("facets") < -1.8
    assert errors[-1] < 2e-3


def test_nsgs_error_follows_its_tolerance() -> None:
    s = study.sweep(
        study.nsgs_tolerance,
        {"tol": [1e-2, 1e-4, 1e-6, 1e-8]},
        reference_settings={"tol": 1e-14},
        quantities=["normal_impulse"],
    )
    assert set(s.reference) == {"normal_impulse"}
    assert 0.8 < s.order("tol") < 1.2
    iters = [r["iterations"] for r in s.records]
    assert iters == sorted(iters) and iters[0] < iters[-1]
    for r in s.records:
        assert r["error"] < 10 * r["tol"]


def test_regularized_creep_is_first_order_in_eps() -> None:
    s = study.sweep(study.regularized_ramp, {"eps": [1e-1, 1e-2, 1e-3]}, reference={"creep": 0.0})
    assert 0.9 < s.order("eps") < 1.1
    assert s.records[-1]["error_creep"] == pytest.approx(s.records[-1]["creep"])


def test_pareto_front_is_exactly_the_non_dominated_set() -> None:
    recs = [
        {"error": 1.0, "time": 1.0},
        {"error": 0.5, "time": 2.0},
        {"error": 0.7, "time": 3.0},  # dominated by the second
        {"error": 0.1, "time": 5.0},
        {"error": float("nan"), "time": 0.1},
        {"error": 2.0, "time": 0.5},
    ]
    front = study.pareto_front(recs)
    assert [(r["error"], r["time"]) for r in front] == [
        (2.0, 0.5),
        (1.0, 1.0),
        (0.5, 2.0),
        (0.1, 5.0),
    ]
    for r in recs:
        if r not in front and math.isfinite(r["error"]):
            assert any(f["error"] <= r["error"] and f["time"] <= r["time"] for f in front)


def test_process_pool_gives_the_serial_answers() -> None:
    grid = {"method": ["lemke"], "facets": [4, 8, 16]}
    serial = study.sweep(study.contact_tolerance, grid, reference={"u_t": 0.4})
    lines: list[str] = []
    with ProcessPoolExecutor(max_workers=2) as pool:
        pooled = study.sweep(
            study.contact_tolerance,
            grid,
            reference={"u_t": 0.4},
            executor=pool,
            progress=lines.append,
        )
    assert _strip_time(pooled.records) == _strip_time(serial.records)
    assert len(lines) == 3 and lines[-1].startswith("[3/3]")


def test_local_dask_cluster_gives_the_serial_answers() -> None:
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    grid = {"eps": [1e-1, 1e-2]}
    serial = study.sweep(study.regularized_ramp, grid, reference={"creep": 0.0})
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = study.sweep(
            study.regularized_ramp, grid, reference={"creep": 0.0}, executor=client.get_executor()
        )
    # the workers' linear algebra may round differently in the last bits (threads)
    for a, b in zip(_strip_time(remote.records), _strip_time(serial.records), strict=True):
        assert a.keys() == b.keys()
        for k in a:
            assert a[k] == pytest.approx(b[k], rel=1e-12)


def test_exports_round_trip(tmp_path) -> None:
    s = study.sweep(
        study.contact_tolerance, {"method": ["lemke"], "facets": [4, 8]}, reference={"u_t": 0.4}
    )
    data = json.loads(s.to_json(tmp_path / "s.json"))
    assert [r["facets"] for r in data["records"]] == [4, 8]
    assert data["reference"] == {"u_t": 0.4}
    text = s.to_csv(tmp_path / "s.csv").read_text().splitlines()
    assert text[0].split(",")[:2] == ["method", "facets"] and len(text) == 3
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    ax = s.plot(path=tmp_path / "s.png")
    front = ax.get_lines()[0]
    assert len(front.get_xdata()) == len(s.pareto())
    assert (tmp_path / "s.png").stat().st_size > 1000
    assert "Pareto front" in repr(s)


def test_bad_input() -> None:
    with pytest.raises(InvalidParameterError):
        study.sweep(study.contact_tolerance, {"facets": 8})
    with pytest.raises(InvalidParameterError):
        study.sweep(study.contact_tolerance, [])
    with pytest.raises(InvalidParameterError):
        study.sweep(study.contact_tolerance, {"facets": [8]}, repeat=0)
    with pytest.raises(InvalidParameterError):
        study.sweep(study.contact_tolerance, {"facets": [8]}, reference={"missing": 1.0})
    with pytest.raises(InvalidParameterError):
        study.convergence_order([1.0], [1.0])


def test_cli_study(tmp_path) -> None:
    import re
    import subprocess
    import sys

    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "coulomb.cli",
            "study",
            "facets",
            "--quiet",
            "--json",
            str(tmp_path / "f.json"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    m = re.search(r"measured order of the error in facets: (-?[0-9.]+)", out.stdout)
    assert m and -2.2 < float(m.group(1)) < -1.8
    assert len(json.loads((tmp_path / "f.json").read_text())["records"]) == 6
    listing = subprocess.run(
        [sys.executable, "-m", "coulomb.cli", "study", "--list"], capture_output=True, text=True
    )
    assert "nsgs-tolerance" in listing.stdout


def test_ramp_front_falls_with_h_at_first_order() -> None:
    s = study.run_preset("ramp-h")
    for solver in ("nsgs", "lemke"):
        rows = [r for r in s.records if r["solver"] == solver]
        errors = [r["error"] for r in rows]  # h decreasing along the grid
        assert all(a > b for a, b in itertools.pairwise(errors)), (solver, errors)
        assert 0.9 < s.order("h", where={"solver": solver}) < 1.1
        assert all(r["creep"] < 1e-9 and r["success"] for r in rows)


def test_painleve_jam_impulse_converges_at_first_order() -> None:
    s = study.run_preset("painleve-h")
    errors = [r["error"] for r in s.records]  # h decreasing along the grid
    assert all(a > b for a, b in itertools.pairwise(errors)), errors
    assert 0.9 < s.order("h") < 1.1
    assert s.records[-1]["error"] < 5e-4
    assert all(r["success"] for r in s.records)


def test_fifty_ramp_settings_with_progress() -> None:
    grid = {
        "h": [1e-1, 5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3],
        "solver": ["nsgs", "lemke"],
        "tol": [1e-6, 1e-9],
        "warm_start": [True, False],
    }
    points = [dict(zip(grid, v, strict=True)) for v in itertools.product(*grid.values())][:50]
    lines: list[str] = []
    s = study.sweep(study.ramp, points, reference={"stop_distance": 1.5053}, progress=lines.append)
    assert len(s) == 50 and len(lines) == 50 and lines[-1].startswith("[50/50]")
    assert all(r["success"] for r in s.records)
    front = s.pareto()
    assert front and all(math.isfinite(r["error"]) for r in front)


def test_impact_is_exact_at_every_step_size_and_phase() -> None:
    s = study.run_preset("impact-h")
    assert len(s) == 15
    assert max(r["error"] for r in s.records) < 1e-12
    assert all(r["success"] for r in s.records)


def test_ramp_sweeps_iteration_limit_and_drift_correction() -> None:
    s = study.sweep(
        study.ramp,
        {"h": [1e-2], "max_iter": [1, 1000], "drift": ["none", "bias", "projection"]},
        reference={"stop_distance": 1.5053},
    )
    assert len(s) == 6
    # one contact: NSGS is exact in one sweep, so neither setting moves the stop distance
    errors = {round(r["error"], 12) for r in s.records}
    assert len(errors) == 1 and all(r["success"] for r in s.records)
