"""The extremes suite, reduced form: every case meets its bound or warns with its cause."""

from __future__ import annotations

import math
import warnings

from coulomb import extremes


def test_reduced_suite_meets_its_bounds_or_says_why() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cases = extremes.run()
    warned = {str(w.message).split(":")[0] for w in caught if w.category is extremes.ExtremeWarning}
    families = {c.family for c in cases}
    assert families == {
        "mass ratio",
        "friction",
        "restitution",
        "step size",
        "grazing impact",
        "redundant contacts",
        "units",
        "Painleve rod",
    }
    for c in cases:
        assert math.isfinite(c.measured), c
        assert c.honest, f"false success: {c}"
        assert c.passed or f"{c.family}, {c.case}" in warned, c


def test_report_marks_every_case() -> None:
    case = extremes.ExtremeCase("units", "x", "q", 2.0, 1.0, True, "ok", 0.0)
    assert not case.passed and not case.honest
    text = extremes.format_report([case])
    assert "FALSE SUCCESS" in text
    ok = extremes.ExtremeCase("units", "x", "q", 0.5, 1.0, True, "ok", 0.0)
    assert ok.passed and "| pass |" in extremes.format_report([ok])
