"""Reproduce the reference figures of the chapter and report each against its value.

``coulomb validate`` prints the table; :func:`run` returns its rows. Each row compares a
figure computed by coulomb with the figure the chapter states (Satici, *Kinematics and Machine
Dynamics*, ch. 11, after Stewart, SIAM Review 42(1), 2000), within a stated tolerance.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import contact, lcp
from .io import read_siconos_lcp
from .painleve import PainleveRod

__all__ = ["Row", "format_table", "run"]


@dataclass(frozen=True)
class Row:
    """One reproduced figure."""

    case: str
    quantity: str
    expected: float | str
    computed: float | str
    tolerance: float | None
    passed: bool


def _num(case: str, quantity: str, expected: float, computed: float, tol: float) -> Row:
    return Row(case, quantity, expected, computed, tol, abs(computed - expected) <= tol)


def _text(case: str, quantity: str, expected: str, computed: str) -> Row:
    return Row(case, quantity, expected, computed, None, expected == computed)


def _lcp_rows() -> Iterator[Row]:
    case = "scalar LCP w = 2z - 6"
    r = lcp.solve([[2.0]], [-6.0])
    yield _num(case, "z", 3.0, float(r.z[0]), 1e-12)
    yield _num(case, "w", 0.0, float(r.w[0]), 1e-12)
    yield _text(case, "status", "solved", r.status)
    case = "scalar LCP w = -z - 1"
    r = lcp.solve([[-1.0]], [-1.0])
    yield _text(case, "status (no solution)", "ray_termination", r.status)
    yield _text(case, "success", "False", str(bool(r.success)))


def _contact_rows() -> Iterator[Row]:
    # the chapter's inelastic contact step: a 2 kg particle hits a fixed floor with e = 0,
    # v_n^- = -3 m/s, v_t^- = 1 m/s, mu = 0.2; W = I/m and q = v^- (no free-flight term)
    m = 2.0
    for dim, q in ((2, [-3.0, 1.0]), (3, [-3.0, 1.0, 0.0])):
        case = f"inelastic contact step ({dim}D)"
        r = contact.solve(np.eye(dim) / m, q, 0.2, dim=dim, tol=1e-12)
        p, u = r.impulse[0], r.velocity[0]
        yield _num(case, "P_n (N s)", 6.0, float(p[0]), 1e-9)
        yield _num(case, "P_t (N s)", -1.2, float(p[1]), 1e-9)
        yield _num(case, "v_t^+ (m/s)", 0.4, float(u[1]), 1e-9)
        yield _num(case, "v_n^+ (m/s)", 0.0, float(u[0]), 1e-9)
        yield _num(case, "T^+ (J)", 0.16, float(0.5 * m * (u @ u)), 1e-9)


def _painleve_rows() -> Iterator[Row]:
    # the chapter's rod: m = 1 kg, l = 1 m, J = 1/12 kg m^2, mu = 2, theta = 45 deg, sliding left
    case = "Painleve rod, theta = 45 deg"
    rod = PainleveRod(m=1.0, l=1.0, J=1.0 / 12.0, mu=2.0)
    res = rod.analyze(np.radians(45.0), 0.0, slip=-1.0)
    yield _num(case, "A (1/kg)", -0.5, float(res.A), 1e-12)
    yield _num(case, "b (m/s^2)", -9.81, float(res.b), 1e-12)
    yield _text(case, "sliding mode with N >= 0", "none", ", ".join(res.modes) or "none")


def _stepper_rows() -> Iterator[Row]:
    from ._step_figures import rows

    for case, quantity, expected, computed, tol in rows():
        yield _num(case, quantity, expected, computed, tol)


def default_data_dir() -> Path | None:
    """``$COULOMB_DATA``, else ``../shared/data`` beside a source checkout, else the sets a
    checkout ships in ``tests/data`` (when run from the checkout's root), if present."""
    env = os.environ.get("COULOMB_DATA")
    candidates = [Path(env)] if env else []
    checkout = Path(__file__).resolve().parents[2]
    candidates.append(Path.cwd().parent / "shared" / "data")
    candidates.append(checkout.parent / "shared" / "data")
    candidates.append(Path.cwd() / "tests" / "data")
    for c in candidates:
        if (c / "siconos-lcp").is_dir():
            return c
    return None


def _data_rows(data: Path) -> Iterator[Row]:
    folder = data / "siconos-lcp"
    files = sorted(folder.glob("lcp_*.dat"))
    # Problems without a solution (enumeration finds none, or Lemke's theory allows a ray):
    # documented in SOURCE.md and checked by the test suite.
    no_solution_expected = {"lcp_CPS_3", "lcp_Pang_isolated_sol_perturbed"}
    solved = 0
    honest = 0
    for f in files:
        p = read_siconos_lcp(f)
        r = lcp.solve(p.M, p.q)
        if p.name in no_solution_expected:
            honest += int(not r.success)
        else:
            solved += int(r.success and r.error <= 1e-10)
    expected = len(files) - len(no_solution_expected)
    yield _text(
        "Siconos LCP set", "solved to 1e-10", f"{expected}/{expected}", f"{solved}/{expected}"
    )
    yield _text("Siconos LCP set", "no false success", "2/2", f"{honest}/2")
    murty = read_siconos_lcp(folder / "lcp_exp_murty2.dat")
    r = lcp.solve(murty.M, murty.q, covering_vector=np.ones(murty.n))
    yield _num("Murty's example, n = 6", "Lemke pivots (2^n)", 64.0, float(r.pivots), 0.0)


def run(data: Path | None = None, progress: Callable[[str], None] | None = None) -> list[Row]:
    """Every row: the chapter's figures, then (if the benchmark data is found) the data set's."""
    rows = [*_lcp_rows(), *_contact_rows(), *_painleve_rows(), *_stepper_rows()]
    data = data or default_data_dir()
    if data is not None:
        if progress:
            progress(f"benchmark data: {data}")
        rows.extend(_data_rows(data))
    elif progress:
        progress(
            "benchmark data not found (set COULOMB_DATA): the chapter's worked examples only"
        )
    return rows


def _fmt(v: float | str) -> str:
    """Six significant digits; exact zeros as ``0`` (a signed zero as ``0`` too)."""
    if isinstance(v, float):
        return "0" if v == 0.0 else f"{v:.6g}"
    return str(v)


def _fmt_tol(tol: float | None) -> str:
    return "exact" if tol in (None, 0.0) else f"{tol:.0e}"


def format_table(rows: list[Row]) -> str:
    """A plain-text table of the rows: the expected value (from the literature, or the
    closed form), coulomb's, the tolerance and whether it is met."""
    head = ("case", "quantity", "expected", "coulomb", "tolerance", "result")
    body = [
        (
            r.case,
            r.quantity,
            _fmt(r.expected),
            _fmt(r.computed),
            _fmt_tol(r.tolerance),
            "ok" if r.passed else "FAIL",
        )
        for r in rows
    ]
    widths = [max(len(str(x[i])) for x in [head, *body]) for i in range(len(head))]
    lines = ["  ".join(str(c).ljust(w) for c, w in zip(head, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths).rstrip())
    for b in body:
        lines.append("  ".join(str(c).ljust(w) for c, w in zip(b, widths, strict=True)).rstrip())
    passed = sum(r.passed for r in rows)
    lines.append(f"\n{passed} of {len(rows)} figures reproduced")
    return "\n".join(lines)
