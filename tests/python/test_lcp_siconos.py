"""The Siconos LCP test set (../shared/data/siconos-lcp, see SOURCE.md there).

Oracles: enumeration of every complementary basis (n <= 15), an independent Lemke in exact
rational arithmetic (exact_lemke.py, any n), and the analytic answers of the structured
problems.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SICONOS_LCP_NAMES
from coulomb import lcp
from coulomb.io import read_siconos_lcp
from exact_lemke import lemke as exact_lemke
from helpers import lcp_error, rel_diff

LARGE = ("lcp_mmc", "lcp_tobenna")  # n > 15: beyond enumeration
# Lemke (any covering vector) ends on a secondary ray: CPS_3 is a bimatrix game whose M is
# not copositive-plus (enumeration finds solutions Lemke's path cannot reach; Siconos
# expects every Lemke variant to fail), Pang_isolated_sol_perturbed has no solution at all.
RAY = ("lcp_CPS_3", "lcp_Pang_isolated_sol_perturbed")
SMALL = tuple(n for n in SICONOS_LCP_NAMES if n not in LARGE)


def load(folder, name):
    return read_siconos_lcp(folder / f"{name}.dat")


def test_data_set_is_the_documented_one(siconos_lcp_dir):
    found = sorted(p.stem for p in siconos_lcp_dir.glob("lcp_*.dat"))
    assert found == sorted(SICONOS_LCP_NAMES)


@pytest.mark.parametrize(
    "name, n",
    [("lcp_CPS_1", 2), ("lcp_tobenna", 40), ("lcp_mmc", 26), ("lcp_enum_fails", 9)],
)
def test_sizes_from_source_md(siconos_lcp_dir, name, n):
    p = load(siconos_lcp_dir, name)
    assert p.name == name
    assert p.n == n
    assert p.M.shape == (n, n)
    assert p.q.shape == (n,)


@pytest.mark.parametrize("stem", ["lcp_deudeu", "lcp_ortiz", "lcp_trivial"])
def test_block_storage_reads_as_dense(siconos_lcp_dir, stem):
    dense = load(siconos_lcp_dir, stem)
    block = load(siconos_lcp_dir, f"{stem}_block")
    np.testing.assert_array_equal(dense.M, block.M)
    np.testing.assert_array_equal(dense.q, block.q)


def test_dense_storage_is_column_major(siconos_lcp_dir):
    # Murty's M is upper triangular (1 on the diagonal, 2 above); the file prints its columns.
    p = load(siconos_lcp_dir, "lcp_exp_murty2")
    expected = np.triu(np.full((6, 6), 2.0), 1) + np.eye(6)
    np.testing.assert_array_equal(p.M, expected)
    np.testing.assert_array_equal(p.q, [-126, -124, -120, -112, -96, -64])


@pytest.mark.parametrize("name", [n for n in SMALL if n not in RAY])
def test_lemke_solves_what_enumeration_solves(siconos_lcp_dir, name):
    p = load(siconos_lcp_dir, name)
    assert p.n <= 15
    e = lcp.solve(p.M, p.q, method="enumerate")
    assert len(e.solutions) >= 1, "the oracle finds a solution"
    for s in e.solutions:
        assert lcp_error(p.M, p.q, s) <= 1e-9
    r = lcp.solve(p.M, p.q)
    assert r.success is True
    assert r.status == "solved"
    assert r.error <= 1e-10
    assert lcp_error(p.M, p.q, r.z) <= 1e-10
    if len(e.solutions) == 1 and name != "lcp_enum_fails":
        # A unique vertex solution (and not the degenerate "enum_fails" case, whose
        # solution set need not be a single point): Lemke must find that one.
        assert rel_diff(r.z, e.solutions[0]) <= 1e-9


@pytest.mark.parametrize("name", RAY)
def test_no_false_success(siconos_lcp_dir, name):
    p = load(siconos_lcp_dir, name)
    r = lcp.solve(p.M, p.q)
    assert r.success is False
    assert r.status == "ray_termination"
    # The ray is the mathematics, not a rounding accident: exact Lemke ends there too.
    assert exact_lemke(p.M.tolist(), p.q.tolist()).status == "ray_termination"


def test_pang_perturbed_has_no_solution(siconos_lcp_dir):
    p = load(siconos_lcp_dir, "lcp_Pang_isolated_sol_perturbed")
    e = lcp.solve(p.M, p.q, method="enumerate")
    assert e.success is False
    assert len(e.solutions) == 0


@pytest.mark.parametrize("name", SICONOS_LCP_NAMES)
def test_textbook_lemke_matches_exact_lemke(siconos_lcp_dir, name):
    """With covering vector ones coulomb follows exactly the exact-arithmetic pivot path."""
    p = load(siconos_lcp_dir, name)
    ex = exact_lemke(p.M.tolist(), p.q.tolist())
    r = lcp.solve(p.M, p.q, covering_vector=np.ones(p.n))
    assert r.status == ex.status
    assert r.pivots == ex.pivots
    if ex.status == "solved":
        # The oracle's answer is exactly complementary, in rationals.
        assert min(ex.z) >= 0 and min(ex.w) >= 0
        assert sum(a * b for a, b in zip(ex.z, ex.w, strict=True)) == 0
        z = np.array([float(x) for x in ex.z])
        assert r.success is True
        assert rel_diff(r.z, z) <= 1e-9
        assert sorted(r.basis.tolist()) == ex.basis


@pytest.mark.parametrize("name", LARGE)
def test_large_problems_default_lemke(siconos_lcp_dir, name):
    p = load(siconos_lcp_dir, name)
    assert p.n > 15
    r = lcp.solve(p.M, p.q)
    assert r.success is True
    assert r.error <= 1e-10
    assert lcp_error(p.M, p.q, r.z) <= 1e-10
    if name == "lcp_mmc":
        # SPD: the solution is unique, so it is the exact Lemke's.
        ex = exact_lemke(p.M.tolist(), p.q.tolist())
        assert rel_diff(r.z, np.array([float(x) for x in ex.z])) <= 1e-9


def test_tobenna_known_answer(siconos_lcp_dir):
    p = load(siconos_lcp_dir, "lcp_tobenna")
    ex = exact_lemke(p.M.tolist(), p.q.tolist())
    assert ex.status == "solved"
    # Exact complementarity of the oracle's answer, in rationals.
    assert all(x >= 0 for x in ex.z) and all(x >= 0 for x in ex.w)
    assert sum(a * b for a, b in zip(ex.z, ex.w, strict=True)) == 0
    r = lcp.solve(p.M, p.q, covering_vector=np.ones(40))
    assert r.pivots == ex.pivots
    assert rel_diff(r.z, np.array([float(x) for x in ex.z])) <= 1e-9


def test_cps5_degenerate_tie(siconos_lcp_dir):
    # CPS Example 4.4.16: M = [[1, -1], [-1, 1]], q = [1, -1]. Every solution has
    # w1 + w2 = 0, hence w = 0 and z2 = z1 + 1; Lemke must let z0 leave on the tie.
    p = load(siconos_lcp_dir, "lcp_CPS_5")
    for cover in (None, np.ones(2)):
        r = lcp.solve(p.M, p.q, covering_vector=cover)
        assert r.success is True
        assert r.error <= 1e-10
        np.testing.assert_allclose(r.w, [0.0, 0.0], atol=1e-12)
        assert r.z[1] - r.z[0] == pytest.approx(1.0, abs=1e-12)
        assert r.z.min() >= 0.0


def test_murty_exponential_example(siconos_lcp_dir):
    p = load(siconos_lcp_dir, "lcp_exp_murty2")
    r = lcp.solve(p.M, p.q, covering_vector=np.ones(6))
    assert r.pivots == 64 == 2**6
    assert r.success is True
    # Analytic answer: z = 2^n e_n, w_i = 2^(i+1) for i < n-1.
    np.testing.assert_allclose(r.z, [0, 0, 0, 0, 0, 64], atol=1e-12)
    np.testing.assert_allclose(r.w, [2, 4, 8, 16, 32, 0], atol=1e-12)


@pytest.mark.parametrize("stem", ["lcp_trivial", "lcp_trivial_block", "lcp_exp_murty"])
def test_analytic_answers(siconos_lcp_dir, stem):
    p = load(siconos_lcp_dir, stem)
    r = lcp.solve(p.M, p.q)
    assert r.success is True
    if stem.startswith("lcp_trivial"):
        # diag(1..9) z = 1: z_i = 1 / i.
        expected = 1.0 / np.arange(1, 10)
    else:
        # Murty's M with q = -1: z = e_n (w = (1, ..., 1, 0)).
        expected = np.eye(6)[5]
    np.testing.assert_allclose(r.z, expected, rtol=1e-14, atol=1e-14)
