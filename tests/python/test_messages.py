"""Messages print errors and tolerances readably and alike in every solver: ``0`` for zero,
two significant digits otherwise (``1.2e-15``, ``1e-9``), never ``0.00e0`` or ``e+00``; the
Python layer formats as the Rust core does."""

from __future__ import annotations

import re

import coulomb
import numpy as np
import pytest
from coulomb._readable import readable

UNREADABLE = re.compile(r"\d\.\d{2}e|e\+|e-0\d|0\.0+e")
NUMBER = r"(0|-?\d(?:\.\d)?e-?\d+|inf|NaN)"


@pytest.mark.parametrize(("x", "text"), [
    (0.0, "0"), (-0.0, "0"), (1.23e-15, "1.2e-15"), (1e-9, "1e-9"), (-2.5e3, "-2.5e3"),
    (0.5, "5e-1"), (9.96e-3, "1e-2"), (float("inf"), "inf"), (float("nan"), "NaN"),
])
def test_readable_numbers_match_the_core_rule(x: float, text: str) -> None:
    assert readable(x) == text


def test_an_exact_lemke_answer_says_error_0() -> None:
    r = coulomb.lcp.solve([[2.0]], [-6.0])  # z = 3, w = 0: no rounding anywhere
    assert r.error == 0.0
    assert r.message == "solved in 2 pivots (error 0, polished)"


def test_lcp_messages_carry_the_measured_error_and_tol_readably() -> None:
    rng = np.random.default_rng(3)
    a = rng.standard_normal((8, 8))
    M, q = a @ a.T + 0.1 * np.eye(8), rng.standard_normal(8)
    r = coulomb.lcp.solve(M, q, "pgs", max_iter=2, tol=1e-12)
    assert not r.success
    m = re.fullmatch(rf"stopped at max_iter = 2 with error {NUMBER} > tol {NUMBER}", r.message)
    assert m, r.message
    assert m.group(1) == readable(r.error) and m.group(2) == "1e-12"
    for method in ("lemke", "pgs", "enumerate"):
        text = coulomb.lcp.solve(M, q, method).message
        assert not UNREADABLE.search(text), text


def test_contact_messages_carry_the_measured_error_and_tol_readably() -> None:
    W = np.eye(6) / 2
    q = np.array([-3.0, 1.0, 0.5, -1.0, 0.2, 0.0])
    r = coulomb.contact.solve(W, q, 0.2, dim=3, max_iter=1, tol=1e-14)
    m = re.search(rf"scaled_error {NUMBER}", r.message)
    assert m and m.group(1) == readable(r.scaled_error), r.message
    for method in ("nsgs", "lemke", "prox"):
        for dim in (2, 3):
            text = coulomb.contact.solve(W, q, 0.2, dim=dim, method=method).message
            assert not UNREADABLE.search(text), text


def test_prox_messages_print_the_scaled_error_and_tol_readably() -> None:
    rng = np.random.default_rng(5)
    a = rng.standard_normal((12, 12))
    W = a @ a.T / 12 + 0.1 * np.eye(12)
    q = rng.standard_normal(12)
    r = coulomb.contact.solve(W, q, 0.5, dim=3, method="prox", max_iter=1, tol=1e-14)
    assert not UNREADABLE.search(r.message), r.message
    if not r.success:
        m = re.search(rf"scaled_error {NUMBER} > tol {NUMBER}", r.message)
        assert m, r.message
        assert m.group(1) == readable(r.scaled_error) and m.group(2) == "1e-14"


def test_trajectory_check_messages_print_residuals_readably() -> None:
    scene = coulomb.Scene(dim=2)
    ball = scene.add(coulomb.Particle(mass=1.0, position=(0.0, 0.0), velocity=(0.0, -1.0)))
    scene.contact(scene.attach(ball, coulomb.Point()), scene.add(coulomb.HalfSpace()), e=1.0)
    tr = scene.simulate(0.01, 1e-3)
    report = tr.check(momentum_tol=1e-300)  # any rounding in the balance is a violation
    worst = max(tr.momentum_residual)
    if worst > 1e-300:
        assert f"momentum residual up to {readable(worst)} > 1e-300" in report.violations
    assert not any(UNREADABLE.search(v) for v in report.violations)
    assert not UNREADABLE.search(repr(tr).split("min gap")[0] + repr(tr).split("worst:")[1])
