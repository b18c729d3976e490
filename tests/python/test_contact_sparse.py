"""coulomb.contact.solve with a scipy.sparse W (stored block-sparse by the core, never
densified) and with anisotropic friction (an ellipse per contact, mu of shape (nc, 2))."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from coulomb import _core, contact, errors
from coulomb.io import FrictionContactProblem, read_siconos_fc
from helpers import (
    available_dir,
    contact_error,
    contact_scaled_error,
    count_during,
    project_coulomb_cone,
)
from hypothesis import given, settings
from hypothesis import strategies as st


def random_problem(seed: int, nc: int, dim: int = 3, mu: float = 0.3, density: float = 0.3):
    """W = G^T G / 4 with a sparse G (so W has zero tiles), q pushing every contact closed."""
    rng = np.random.default_rng(seed)
    ndof = 6 * (nc // 4) + 3
    G = rng.standard_normal((ndof, dim * nc)) * (rng.random((ndof, dim * nc)) < density)
    W = G.T @ G / 4.0
    q = rng.standard_normal(dim * nc)
    q[::dim] = -np.abs(q[::dim]) - 0.5
    return W, q, np.full(nc, mu)


def pile(seed: int, nc: int, mu: float = 0.4):
    """A pile of bodies (6 velocities each, diagonal mass): contact k touches body k // 2 and
    one a few places further, so W = G^T M^-1 G has a few 3 x 3 tiles per block row. W is
    built sparse."""
    rng = np.random.default_rng(seed)
    nb = nc // 2 + 2
    rows, cols, vals = [], [], []
    for k in range(nc):
        a = k // 2
        b = a + 1 + int(rng.integers(3))
        for body, sign in ((a, 1.0), (b, -1.0)):
            if body >= nb:
                continue
            J = sign * rng.standard_normal((6, 3))
            for x in range(6):
                for c in range(3):
                    rows.append(6 * body + x)
                    cols.append(3 * k + c)
                    vals.append(J[x, c])
    G = sp.csr_array((vals, (rows, cols)), shape=(6 * nb, 3 * nc))
    Minv = sp.diags_array(1.0 / rng.uniform(0.5, 2.0, 6 * nb))
    W = (G.T @ Minv @ G).tocsr()
    q = G.T @ rng.standard_normal(6 * nb)
    q[::3] -= rng.uniform(0.5, 2.0, nc)
    return W, q, np.full(nc, mu)


def same(a, b):
    np.testing.assert_array_equal(a.impulse, b.impulse)
    np.testing.assert_array_equal(a.velocity, b.velocity)
    assert a.iterations == b.iterations and a.status == b.status
    assert a.error == b.error and a.error_q == b.error_q
    assert a.cone_violation == b.cone_violation


FORMATS = {
    "csr_array": sp.csr_array,
    "csr_matrix": sp.csr_matrix,
    "csc_array": sp.csc_array,
    "coo_matrix": sp.coo_matrix,
    "coo_array": sp.coo_array,
    "bsr_dim": lambda W: sp.bsr_array(W, blocksize=(3, 3)),
    "bsr_1": lambda W: sp.bsr_matrix(W, blocksize=(1, 1)),
    "lil": sp.lil_matrix,
}


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@pytest.mark.parametrize("seed", [0, 1])
def test_sparse_formats_give_the_dense_answer_exactly(fmt, seed):
    W, q, mu = random_problem(seed, nc=12)
    dense = contact.solve(W, q, mu)
    assert dense.success, dense.message
    sparse = contact.solve(FORMATS[fmt](W), q, mu)
    same(dense, sparse)


@pytest.mark.parametrize("seed", [2, 3])
def test_sparse_2d_with_options(seed):
    W, q, mu = random_problem(seed, nc=10, dim=2)
    kw = {"relaxation": 1.2, "initial": np.full((10, 2), 0.05), "tol": 1e-10}
    same(contact.solve(W, q, mu, dim=2, **kw), contact.solve(sp.csc_array(W), q, mu, dim=2, **kw))
    lem = contact.solve(W, q, mu, dim=2, method="lemke")
    same(lem, contact.solve(sp.coo_array(W), q, mu, dim=2, method="lemke"))
    assert lem.success


def test_a_sparse_pile_is_solved_and_matches_dense():
    W, q, mu = pile(0, nc=120)
    assert W.nnz < 0.15 * W.shape[0] ** 2
    s = contact.solve(W, q, mu, max_iter=5000)
    assert s.success, s.message
    err = contact_error(W.toarray(), q, mu, 3, s.impulse)[0]
    assert s.error == pytest.approx(err, rel=1e-9)
    assert contact_scaled_error(W.toarray(), q, mu, 3, s.impulse) <= 1e-8
    same(s, contact.solve(W.toarray(), q, mu, max_iter=5000))
    # int64 indices and float32 data (exactly representable here after the cast)
    W64 = sp.csr_array(
        (W.data.astype(np.float32), W.indices.astype(np.int64), W.indptr.astype(np.int64)),
        shape=W.shape,
    )
    W32d = W64.toarray().astype(np.float64)
    same(contact.solve(W64, q, mu, max_iter=50), contact.solve(W32d, q, mu, max_iter=50))


def test_unsorted_and_duplicate_entries_are_summed():
    W, q, mu = random_problem(4, nc=6)
    coo = sp.coo_array(W)
    # every entry split into halves, in reversed order: CSR with duplicates, unsorted
    half = 0.5 * coo.data
    rows = np.concatenate([coo.row, coo.row])[::-1]
    cols = np.concatenate([coo.col, coo.col])[::-1]
    data = np.concatenate([half, half])[::-1]
    order = np.argsort(rows, kind="stable")
    indptr = np.searchsorted(rows[order], np.arange(W.shape[0] + 1))
    raw = sp.csr_array((data[order], cols[order], indptr), shape=W.shape)
    assert not raw.has_canonical_format
    a = contact.solve(raw, q, mu)
    b = contact.solve(W, q, mu)
    assert a.success
    np.testing.assert_allclose(a.impulse, b.impulse, rtol=0, atol=1e-9 * np.abs(b.impulse).max())


@pytest.fixture(scope="module")
def fc_set() -> tuple[Path, bool]:
    """The full Siconos friction-contact set if present (required in CI), else the subset
    shipped in tests/data."""
    return available_dir("siconos-fc")


@pytest.fixture(scope="module")
def fc_problems(fc_set: tuple[Path, bool]):
    path, _ = fc_set
    out = {}
    for f in sorted(path.glob("*.dat")):
        if f.stem.startswith("gfc2d_granularflowonwall_00230"):
            continue  # beyond the reader's densification limit (see test_contact_io.py)
        p = read_siconos_fc(f)
        if isinstance(p, FrictionContactProblem) and p.dim * p.nc <= 1500:
            out[f.stem] = p
    return out


def test_siconos_fc_sparse_equals_dense(fc_set, fc_problems):
    # includes the files stored sparse-block or CSparse on disk (FC3D_Example1_SBM,
    # Confeti-*-SBM, ...): the reader densifies, scipy gives back the sparse W
    _, full = fc_set
    assert len(fc_problems) >= (40 if full else 33)
    stored = 0
    for name, p in fc_problems.items():
        Ws = sp.csr_array(p.W)
        stored += Ws.nnz < p.W.size
        a = contact.solve(p.W, p.q, p.mu, p.dim, tol=1e-8, max_iter=100)
        b = contact.solve(Ws, p.q, p.mu, p.dim, tol=1e-8, max_iter=100)
        np.testing.assert_array_equal(a.impulse, b.impulse, err_msg=name)
        assert (a.iterations, a.error) == (b.iterations, b.error), name
    assert stored >= (20 if full else 12)


def test_sparse_input_errors():
    q = np.array([-3.0, 1.0, 0.0])
    W = sp.csr_array(np.eye(3) / 2)
    with pytest.raises(errors.ShapeError, match="W must have shape"):
        contact.solve(sp.csr_array(np.eye(6)), q, 0.2)
    with pytest.raises(errors.ShapeError, match="W must have shape"):
        contact.solve(sp.csr_array(np.ones((3, 2))), q, 0.2)
    bad = W.copy()
    bad.data[1] = np.nan
    with pytest.raises(errors.NonFiniteError, match="W"):
        contact.solve(bad, q, 0.2)
    with pytest.raises(errors.InvalidInputError, match="real"):
        contact.solve(sp.csr_array(np.eye(3) * 1j), q, 0.2)
    # the core checks the raw arrays
    ip, ix, d = np.array([0, 1, 2, 3]), np.array([0, 1, 3]), np.ones(3)
    with pytest.raises(errors.ShapeError, match="out of range"):
        _core.contact_solve(None, q, np.array([0.2]), 3, "nsgs", 1e-8, w_csr=(3, ip, ix, d))
    with pytest.raises(errors.ShapeError, match="indptr"):
        _core.contact_solve(
            None, q, np.array([0.2]), 3, "nsgs", 1e-8, w_csr=(3, ip[::-1].copy(), ix, d)
        )
    with pytest.raises(errors.ShapeError, match="same integer type"):
        _core.contact_solve(
            None, q, np.array([0.2]), 3, "nsgs", 1e-8, w_csr=(3, ip.astype(np.int32), ix, d)
        )
    with pytest.raises(errors.InvalidParameterError, match="exactly one"):
        _core.contact_solve(np.eye(3), q, np.array([0.2]), 3, "nsgs", 1e-8, w_csr=(3, ip, ix, d))
    with pytest.raises(errors.ShapeError, match="whole number"):
        _core.contact_solve(
            None, q[:2], np.array([0.2]), 3, "nsgs", 1e-8, w_csr=(2, ip[:3], ix[:2], d[:2])
        )


def test_large_sparse_solve_releases_the_gil():
    W, q, mu = pile(1, nc=3000)
    r, count = count_during(lambda: contact.solve(W, q, mu, tol=1e-300, max_iter=200))
    assert r.iterations == 200
    # see helpers.count_during: a GIL-holding call lets the main thread count to at most ~600
    assert count > 20_000


# --- anisotropic friction ------------------------------------------------------------------


def ellipse_brute(x, a: float, b: float) -> np.ndarray:
    """The nearest point to x of the ellipse (y1 / a)^2 + (y2 / b)^2 <= 1, by brute force: x
    itself if inside, else a fine grid over the boundary angle refined by golden sections."""
    x = np.asarray(x, dtype=float)
    if (x[0] / a) ** 2 + (x[1] / b) ** 2 <= 1.0:
        return x

    def f(t):
        return (a * np.cos(t) - x[0]) ** 2 + (b * np.sin(t) - x[1]) ** 2

    grid = np.linspace(0.0, 2 * np.pi, 20001)
    k = int(np.argmin(f(grid)))
    # the angle is periodic: bracket across 0 = 2 pi instead of clamping at the grid's ends
    step = grid[1] - grid[0]
    lo, hi = grid[k] - step, grid[k] + step
    g = (np.sqrt(5.0) - 1) / 2
    for _ in range(100):
        c, d = hi - g * (hi - lo), lo + g * (hi - lo)
        if f(c) < f(d):
            hi = d
        else:
            lo = c
    t = 0.5 * (lo + hi)
    return np.array([a * np.cos(t), b * np.sin(t)])


def elliptic_error(W, q, pairs, r) -> float:
    """The natural-map residual of the elliptic cones, recomputed here: with m = max(mu_1,
    mu_2), B = diag(1, mu_1 / m, mu_2 / m), r = B r^ and u^ = B u map the problem to the
    isotropic cone of coefficient m; the residual r - B P_{K_m}(B^-1 r - (u^ + m ||u^_t|| n)),
    divided by max(||q||, ||r||, ||u||)."""
    r = np.asarray(r, dtype=float).reshape(-1)
    u = W @ r + q
    res = np.empty_like(r)
    for i, (m1, m2) in enumerate(pairs):
        s = slice(3 * i, 3 * i + 3)
        m = max(m1, m2)
        B = np.array([1.0, m1 / m, m2 / m])
        rh, uh = r[s] / B, u[s] * B
        v = rh - uh
        v[0] -= m * np.linalg.norm(uh[1:])
        res[s] = r[s] - B * project_coulomb_cone(v, m)
    denom = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    return float(np.linalg.norm(res) / denom)


@pytest.mark.parametrize("axis", [1, 2])
def test_anisotropic_sliding_along_a_principal_axis(axis):
    # the seed's step (m = 2, v_n = -3) sliding along tangent `axis` with mu_axis = 0.2 and
    # 0.5 across it: P_t = -mu_axis P_n = -1.2, the slip is 1 - 1.2 / 2 = 0.4
    W = np.eye(3) / 2
    q = np.array([-3.0, 0.0, 0.0])
    q[axis] = 1.0
    pair = [0.2, 0.5] if axis == 1 else [0.5, 0.2]
    for Wx in (W, sp.csr_array(W)):
        r = contact.solve(Wx, q, [pair])
        assert r.success, r.message
        P, u = r.impulse[0], r.velocity[0]
        expect = np.zeros(3)
        expect[0], expect[axis] = 6.0, -1.2
        np.testing.assert_allclose(P, expect, atol=1e-12)
        np.testing.assert_allclose(u[axis], 0.4, atol=1e-12)
        assert abs(u[0]) < 1e-12 and r.error < 1e-14 and r.cone_violation <= 1e-12


def test_anisotropic_oblique_slip_is_the_ellipse_projection():
    # W = I / m: with P_n = 6 fixed, the friction impulse minimises |P_t|^2 / (2 m) + q_t . P_t
    # over the ellipse, i.e. it is the ellipse projection of -m q_t
    W = np.eye(3) / 2
    q = np.array([-3.0, 1.0, 1.0])
    mu = np.array([[0.2, 0.5]])
    r = contact.solve(W, q, mu, tol=1e-14)
    assert r.success
    expect = ellipse_brute(-2.0 * q[1:], 0.2 * 6.0, 0.5 * 6.0)
    np.testing.assert_allclose(r.impulse[0, 1:], expect, atol=1e-8)
    # and it is the maximal-dissipation direction against the post-step slip
    u = r.velocity[0, 1:]
    phi = np.hypot(0.2 * u[0], 0.5 * u[1])
    np.testing.assert_allclose(r.impulse[0, 1:], -6.0 * np.array([0.04, 0.25]) * u / phi, atol=1e-9)
    # the sticking case: a slip the ellipse can stop
    r = contact.solve(W, np.array([-3.0, 0.1, 0.5]), mu)
    np.testing.assert_allclose(r.velocity[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(r.impulse[0], [6.0, -0.2, -1.0], atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_anisotropic_random_problems(seed):
    W, q, _ = random_problem(seed, nc=10, density=0.6)
    rng = np.random.default_rng(seed + 10)
    pairs = rng.uniform(0.05, 0.8, (10, 2))
    for Wx in (W, sp.csr_array(W)):
        r = contact.solve(Wx, q, pairs, tol=1e-10, max_iter=20000)
        assert r.success, r.message
        assert r.error == pytest.approx(elliptic_error(W, q, pairs, r.impulse), rel=1e-8)
    P, u = r.impulse, r.velocity
    for i in range(10):
        m1, m2 = pairs[i]
        level = np.hypot(P[i, 1] / m1, P[i, 2] / m2)
        assert level <= P[i, 0] * (1 + 1e-9) + 1e-12
        phi = np.hypot(m1 * u[i, 1], m2 * u[i, 2])
        if phi > 1e-6 and P[i, 0] > 1e-6:
            # sliding: maximal dissipation over the ellipse
            expect = -P[i, 0] * np.array([m1 * m1 * u[i, 1], m2 * m2 * u[i, 2]]) / phi
            np.testing.assert_allclose(P[i, 1:], expect, atol=1e-6 * np.abs(P).max())
    # the reported error is not the isotropic one: the pairs matter
    iso = contact_error(W, q, pairs.max(axis=1), 3, P)[0]
    assert iso > 1e3 * r.error


def test_anisotropic_equals_isotropic_when_the_pair_is_equal():
    W, q, mu = random_problem(5, nc=8)
    mu = np.linspace(0.1, 0.9, 8)
    a = contact.solve(W, q, mu)
    b = contact.solve(W, q, np.stack([mu, mu], axis=1))
    same(a, b)
    c = contact.solve(W, q, np.stack([mu, mu], axis=1), method="lemke")
    same(c, contact.solve(W, q, mu, method="lemke"))


def test_anisotropic_polyhedral_lemke():
    # the polygon is inscribed in the ellipse: exact when sliding along a principal axis
    W = np.eye(3) / 2
    for q, expect in (([-3.0, 1.0, 0.0], [6.0, -1.2, 0.0]), ([-3.0, 0.0, 2.0], [6.0, 0.0, -3.0])):
        r = contact.solve(W, q, [[0.2, 0.5]], method="lemke")
        assert r.success, r.message
        np.testing.assert_allclose(r.impulse[0], expect, atol=1e-10)
        assert r.error < 1e-12
    # oblique: inside the ellipse, close to the exact answer with many facets
    q = np.array([-3.0, 1.0, 1.0])
    exact = contact.solve(W, q, [[0.2, 0.5]], tol=1e-14).impulse[0]
    r = contact.solve(W, q, [[0.2, 0.5]], method="lemke", facets=128).impulse[0]
    assert np.hypot(r[1] / 0.2, r[2] / 0.5) <= r[0] * (1 + 1e-12)
    assert np.abs(r - exact).max() < 5e-3
    # a random problem: sparse and dense agree
    W, q, _ = random_problem(6, nc=6, density=0.6)
    pairs = np.random.default_rng(6).uniform(0.05, 0.8, (6, 2))
    a = contact.solve(W, q, pairs, method="lemke")
    assert a.success, a.message
    same(a, contact.solve(sp.csr_array(W), q, pairs, method="lemke"))


def test_a_zero_coefficient_forbids_friction_along_its_tangent():
    W = np.eye(3) / 2
    r = contact.solve(W, [-3.0, 1.0, 1.0], [[0.0, 0.4]])
    assert r.success
    np.testing.assert_allclose(r.impulse[0], [6.0, 0.0, -2.0], atol=1e-12)


@pytest.mark.parametrize(
    ("mu", "dim", "exc", "words"),
    [
        (np.full((1, 3), 0.2), 3, errors.ShapeError, "(1, 2)"),
        (np.full((2, 2), 0.2), 3, errors.ShapeError, "(1, 2)"),
        ([[0.2, 0.3]], 2, errors.InvalidParameterError, "dim = 3"),
        ([[0.2, -0.3]], 3, errors.InvalidParameterError, "mu[0, 1]"),
        ([[0.2, np.inf]], 3, errors.NonFiniteError, "mu"),
    ],
)
def test_anisotropic_input_errors(mu, dim, exc, words):
    q = [-3.0, 1.0, 0.0][:dim]
    with pytest.raises(exc) as info:
        contact.solve(np.eye(dim) / 2, q, mu, dim=dim)
    assert words in str(info.value)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    qt=st.tuples(st.floats(-5, 5, allow_nan=False), st.floats(-5, 5, allow_nan=False)),
    m1=st.floats(0.01, 2.0),
    m2=st.floats(0.01, 2.0),
    qn=st.floats(-5.0, -0.1),
    mass=st.floats(0.1, 10.0),
)
def test_one_contact_answer_is_the_ellipse_projection(qt, m1, m2, qn, mass):
    # W = I / mass: P_n = -mass q_n, P_t = the projection of -mass q_t on the ellipse with
    # semi-axes (m1 P_n, m2 P_n), against a brute-force minimiser
    W = np.eye(3) / mass
    q = np.array([qn, qt[0], qt[1]])
    r = contact.solve(W, q, [[m1, m2]], tol=1e-13, max_iter=100)
    assert r.success, r.message
    pn = -mass * qn
    assert r.impulse[0, 0] == pytest.approx(pn, rel=1e-12)
    expect = ellipse_brute(-mass * q[1:], m1 * pn, m2 * pn)
    scale = 1.0 + mass * np.abs(q).max()
    np.testing.assert_allclose(r.impulse[0, 1:], expect, rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("order", ["forward", "backward", "symmetric", "custom"])
def test_sweep_orders_reach_the_same_answer(order):
    from coulomb._presets import _stack_problem

    W, q = _stack_problem(10, 3)
    ref = contact.solve(W, q, 0.5, tol=1e-13, max_iter=100_000)
    arg = np.random.default_rng(0).permutation(10) if order == "custom" else order
    r = contact.solve(W, q, 0.5, tol=1e-11, max_iter=100_000, order=arg)
    assert r.success and ref.success
    np.testing.assert_allclose(r.impulse, ref.impulse, atol=1e-8 * np.abs(ref.impulse).max())


def test_bad_sweep_orders_are_refused():
    W, q = np.eye(6), np.array([-1.0, 0.1, 0.0, -1.0, 0.0, 0.2])
    with pytest.raises(errors.InvalidParameterError):
        contact.solve(W, q, 0.5, order="sideways")
    with pytest.raises(errors.InvalidParameterError):
        contact.solve(W, q, 0.5, order=[0, 0])
    with pytest.raises(errors.InvalidParameterError):
        contact.solve(W, q, 0.5, method="lemke", order="backward")
