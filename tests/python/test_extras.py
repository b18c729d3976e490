"""Optional dependencies: every extra is declared, documented and checked before any work
(simulated missing modules), and ``python -m coulomb`` runs the command line."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import coulomb
import pytest
from coulomb import _extras, cli, regularized, study, validate
from coulomb._extras import EXTRAS, MissingExtraError, require

ROOT = Path(__file__).resolve().parents[2]


def hide(monkeypatch: pytest.MonkeyPatch, package: str) -> None:
    """Makes ``import package`` (and its submodules) fail as if it were not installed."""
    for name in [m for m in sys.modules if m == package or m.startswith(package + ".")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, package, None)


def no_work(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Replaces the study's sweep by a recorder: a check that comes first leaves it empty."""
    calls: list[str] = []

    def sweep(*args, **kwargs):
        calls.append(kwargs.get("name", "?"))
        raise AssertionError("the study ran before its optional dependency was checked")

    monkeypatch.setattr(study, "sweep", sweep)
    return calls


# ---- declared and documented -----------------------------------------------------------------


def pyproject_extras() -> dict[str, list[str]]:
    tomllib = pytest.importorskip("tomllib")
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["project"]["optional-dependencies"]


def requirement_names(reqs: list[str]) -> set[str]:
    return {re.split(r"[<>=\[ ;]", r, maxsplit=1)[0].lower() for r in reqs}


def test_every_extra_is_known_and_all_is_their_union():
    declared = pyproject_extras()
    # docs and test are for developers: no code checks for them
    assert set(declared) == set(EXTRAS) | {"all", "test", "docs"}
    union = set().union(*(requirement_names(declared[e]) for e in EXTRAS))
    assert requirement_names(declared["all"]) == union
    for extra, modules in EXTRAS.items():
        # the modules the code checks for are what the extra installs (dask[distributed]
        # brings distributed)
        names = requirement_names(declared[extra]) | ({"distributed"} if extra == "dask" else set())
        assert set(modules) <= names, extra
    # the test extra installs every optional dependency the tests exercise
    assert union <= requirement_names(declared["test"])
    # and the doc tools, since the test command (README, .ci/run) builds the docs
    assert requirement_names(declared["docs"]) <= requirement_names(declared["test"])


def test_readme_lists_every_extra():
    readme = (ROOT / "README.md").read_text()
    for extra in [*EXTRAS, "all", "test", "docs"]:
        assert re.search(rf"^\| `{extra}` \|", readme, re.M), extra


# ---- the check itself --------------------------------------------------------------------------


def test_require_names_the_extra_and_the_user(monkeypatch):
    hide(monkeypatch, "scipy")
    with pytest.raises(MissingExtraError) as info:
        require("scipy.integrate", extra="ode", what="the thing")
    err = info.value
    assert isinstance(err, ImportError) and err.extra == "ode"
    assert "the thing needs scipy" in str(err) and "pip install 'coulomb[ode]'" in str(err)


def test_require_passes_when_installed_and_refuses_unknown_pairs():
    with pytest.raises(ValueError, match="not a module of the extra"):
        require("numpy", extra="ode", what="x")
    pytest.importorskip("scipy")
    require("scipy.integrate", extra="ode", what="x")  # no exception


def test_simulate_ramp_without_scipy(monkeypatch):
    hide(monkeypatch, "scipy")
    with pytest.raises(MissingExtraError, match=r"coulomb\[ode\]"):
        regularized.simulate_ramp(0.3, 0.4, 1.0, 1.0, 1e-2)


def test_regularized_study_without_scipy_does_no_work(monkeypatch):
    calls = no_work(monkeypatch)
    hide(monkeypatch, "scipy")
    with pytest.raises(MissingExtraError, match=r"study 'regularized-ramp' needs scipy"):
        study.run_preset("regularized-ramp")
    assert calls == []


def test_cli_study_without_scipy_says_so_first(monkeypatch, capsys):
    calls = no_work(monkeypatch)
    hide(monkeypatch, "scipy")
    assert cli.main(["study", "regularized-ramp"]) == 2
    out, err = capsys.readouterr()
    assert calls == [] and out == ""
    assert "coulomb study: error:" in err and "pip install 'coulomb[ode]'" in err
    assert "Traceback" not in err


def test_cli_study_plot_without_matplotlib_says_so_first(monkeypatch, capsys, tmp_path):
    calls = no_work(monkeypatch)
    hide(monkeypatch, "matplotlib")
    png = tmp_path / "x.png"
    assert cli.main(["study", "ramp-h", "--plot", str(png)]) == 2
    out, err = capsys.readouterr()
    assert calls == [] and out == "" and not png.exists()
    assert "coulomb study --plot needs matplotlib" in err and "coulomb[plot]" in err


def test_study_plot_without_matplotlib(monkeypatch):
    s = study.sweep(study.contact_tolerance, {"method": ["lemke"], "facets": [4, 8]})
    hide(monkeypatch, "matplotlib")
    with pytest.raises(MissingExtraError, match=r"coulomb\[plot\]"):
        s.plot()


def test_cli_unknown_study_is_refused(capsys):
    assert cli.main(["study", "no-such-study"]) == 2
    assert "unknown study 'no-such-study'" in capsys.readouterr().err


def test_extras_table_in_the_module_doc_names_every_extra():
    doc = _extras.__doc__ or ""
    for extra in [*EXTRAS, "all", "test"]:
        assert re.search(rf"^{extra}\s", doc, re.M), extra


# ---- python -m coulomb ---------------------------------------------------------------------------


def run_module(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "coulomb", *args], capture_output=True, text=True, timeout=120
    )


def test_python_m_coulomb_is_the_command_line():
    p = run_module("--version")
    assert p.returncode == 0 and p.stdout.strip() == f"coulomb {coulomb.__version__}"
    listed = run_module("study", "--list")
    assert listed.returncode == 0
    assert [line.split()[0] for line in listed.stdout.splitlines()] == list(study.PRESETS)
    bare = run_module()
    assert bare.returncode == 2 and "usage: coulomb" in bare.stderr


def test_python_m_coulomb_validate_reproduces_every_figure(tmp_path, shipped_data):
    p = subprocess.run(
        [sys.executable, "-m", "coulomb", "validate", "--data", str(shipped_data)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert p.returncode == 0, p.stderr
    m = re.search(r"(\d+) of (\d+) figures reproduced", p.stdout)
    assert m and m.group(1) == m.group(2)
    assert "Siconos LCP set" in p.stdout  # the shipped LCP set's rows


# ---- the validate table --------------------------------------------------------------------------


def test_validate_table_has_a_header_for_every_column():
    rows = [
        validate.Row("a case", "z", 3.0, 3.0, 1e-12, True),
        validate.Row("another", "w", 0.0, -0.0, None, True),
        validate.Row("third", "status", "solved", "ray", None, False),
    ]
    lines = validate.format_table(rows).splitlines()
    head, rule, body = lines[0], lines[1], lines[2:5]
    dashes = [m.span() for m in re.finditer(r"-+", rule)]
    assert len(dashes) == 6
    # every column has a header word starting at its dashes
    for start, _ in dashes:
        assert head[start] != " ", head
    assert head.split() == ["case", "quantity", "expected", "coulomb", "tolerance", "result"]
    assert [b.split()[-1] for b in body] == ["ok", "ok", "FAIL"]
    # zeros print as 0 (not 0.00e0 or -0)
    assert body[1].split()[2:4] == ["0", "0"]
    assert "1e-12" in body[0] and "exact" in body[1]
