"""The ``coulomb`` command line: ``validate`` reproduces the chapter's figures, ``solve-lcp``
solves a file."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys

import coulomb
import pytest


def run(args, tmp_path, data=None, exe=None):
    env = dict(os.environ)
    env.pop("COULOMB_DATA", None)
    if data is not None:
        env["COULOMB_DATA"] = str(data)
    cmd = [exe] if exe else [sys.executable, "-m", "coulomb.cli"]
    # cwd: an empty folder, so that validate cannot find ../shared/data by itself
    return subprocess.run(
        [*cmd, *args], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120
    )


def reproduced(stdout):
    m = re.search(r"(\d+) of (\d+) figures reproduced", stdout)
    assert m, stdout
    return int(m.group(1)), int(m.group(2))


def test_validate_seed_rows(tmp_path):
    p = run(["validate"], tmp_path)
    assert p.returncode == 0, p.stderr
    ok, total = reproduced(p.stdout)
    # scalar LCPs, the 2D and 3D inelastic contact steps, Painleve, and the stepped scenes
    assert ok == total >= 30
    assert "FAIL" not in p.stdout
    assert "scalar LCP w = 2z - 6" in p.stdout
    assert "inelastic contact step (3D)" in p.stdout
    assert "Painleve rod, theta = 45 deg" in p.stdout
    assert "ramp stepped (h = 0.001)" in p.stdout
    assert "Siconos" not in p.stdout
    assert "benchmark data not found" in p.stderr


def test_validate_json(tmp_path):
    p = run(["validate", "--json"], tmp_path)
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)
    assert len(rows) >= 5
    assert all(row["passed"] is True for row in rows)
    z = next(r for r in rows if r["case"] == "scalar LCP w = 2z - 6" and r["quantity"] == "z")
    assert z["expected"] == 3.0
    assert abs(z["computed"] - 3.0) <= z["tolerance"]
    ray = [r for r in rows if r["case"] == "scalar LCP w = -z - 1"]
    assert {r["computed"] for r in ray} == {"ray_termination", "False"}
    step = {
        (r["case"], r["quantity"]): r
        for r in rows
        if r["case"].startswith("inelastic contact step")
    }
    for dim in ("2D", "3D"):
        case = f"inelastic contact step ({dim})"
        assert abs(step[case, "P_t (N s)"]["computed"] + 1.2) <= 1e-9
        assert abs(step[case, "T^+ (J)"]["computed"] - 0.16) <= 1e-9


def test_validate_with_data(tmp_path, shipped_data):
    # tests/data holds the whole Siconos LCP set, as the full data folder does
    data_dir = shipped_data
    p = run(["validate", "--json"], tmp_path, data=data_dir)
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)
    assert all(row["passed"] is True for row in rows)
    siconos = [r for r in rows if r["case"] == "Siconos LCP set"]
    assert {r["quantity"] for r in siconos} == {"solved to 1e-10", "no false success"}
    assert {r["computed"] for r in siconos} == {"18/18", "2/2"}
    murty = [r for r in rows if r["case"].startswith("Murty")]
    assert len(murty) == 1 and murty[0]["computed"] == 64.0
    # the table form says the same
    t = run(["validate"], tmp_path, data=data_dir)
    assert t.returncode == 0
    ok, total = reproduced(t.stdout)
    assert ok == total == len(rows)
    assert "FAIL" not in t.stdout
    # and --data overrides the environment
    d = run(["validate", "--json", "--data", str(data_dir)], tmp_path)
    assert len(json.loads(d.stdout)) == len(rows)


def test_solve_lcp_prints_the_result(tmp_path, siconos_lcp_dir):
    path = siconos_lcp_dir / "lcp_deudeu.dat"
    p = run(["solve-lcp", str(path)], tmp_path)
    assert p.returncode == 0, p.stderr
    assert "lcp_deudeu: n = 2" in p.stdout
    assert "success: True" in p.stdout
    assert "status: Status.SOLVED" in p.stdout


def test_solve_lcp_own_file(tmp_path):
    # w = diag(2, 4) z + (-6, -8): z = (3, 2); column-major storage of a diagonal matrix
    path = tmp_path / "lcp_diag.dat"
    path.write_text("2\n0\n2\n2\n2 2\n2 0\n0 4\n-6 -8\n")
    p = run(["solve-lcp", str(path), "--method", "enumerate"], tmp_path)
    assert p.returncode == 0, p.stderr
    assert "lcp_diag: n = 2" in p.stdout
    assert re.search(r"z: \[3\.?0*, 2\.?0*\]", p.stdout), p.stdout


def test_solve_lcp_without_solution_exits_2(tmp_path):
    path = tmp_path / "lcp_none.dat"
    path.write_text("1\n0\n1\n1\n1 1\n-1\n-1\n")  # the chapter's w = -z - 1
    p = run(["solve-lcp", str(path)], tmp_path)
    assert p.returncode == 2
    assert "Status.RAY_TERMINATION" in p.stdout
    assert "success: False" in p.stdout


def test_version(tmp_path):
    p = run(["--version"], tmp_path)
    assert p.returncode == 0
    assert p.stdout.strip() == f"coulomb {coulomb.__version__}"


def test_console_script(tmp_path):
    exe = shutil.which("coulomb")
    if exe is None:
        pytest.skip("the coulomb console script is not on PATH")
    p = run(["validate"], tmp_path, exe=exe)
    assert p.returncode == 0, p.stderr
    assert "FAIL" not in p.stdout
    ok, total = reproduced(p.stdout)
    assert ok == total >= 5
