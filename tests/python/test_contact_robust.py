"""The robust mode, ``coulomb.contact.solve(method="prox")``: the seed's contact step, a
redundant (singular W) four-corner contact, random problems judged by an independent numpy
residual, the Siconos problems on which NSGS stalls, every local siconos-fc problem at 1e-8,
warm start, honest failure, and input errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from coulomb import contact, errors
from coulomb.io import FrictionContactProblem, read_fclib, read_siconos_fc
from helpers import available_dir, contact_error, contact_scaled_error, data_file

TOL = 1e-8


def seed_problem(dim: int):
    """m = 2, e = 0, v_n^- = -3, v_t^- = 1: W = I / m, q = (-3, 1[, 0])."""
    return np.eye(dim) / 2.0, np.array([-3.0, 1.0, 0.0][:dim])


@pytest.mark.parametrize("dim", [2, 3])
def test_seed_inelastic_step(dim):
    W, q = seed_problem(dim)
    r = contact.solve(W, q, 0.2, dim=dim, method="prox", tol=1e-13)
    assert r.success and r.status == "solved"
    np.testing.assert_allclose(r.impulse[0, :2], [6.0, -1.2], atol=1e-10)
    np.testing.assert_allclose(r.velocity[0, :2], [0.0, 0.4], atol=1e-10)
    # kinetic energy 10 J -> 0.16 J
    assert 0.5 * 2.0 * float(r.velocity[0] @ r.velocity[0]) == pytest.approx(0.16, abs=1e-9)
    assert r.error_q <= TOL and r.error <= r.error_q
    # sticking with mu = 0.6
    s = contact.solve(W, q, 0.6, dim=dim, method="prox", tol=1e-13)
    assert s.success and abs(s.velocity[0, 1]) <= 1e-9
    assert np.linalg.norm(s.impulse[0, 1:]) < 0.6 * s.impulse[0, 0]


def cube_g() -> np.ndarray:
    """A unit cube (mass 1, inertia 1/6) on its four bottom corners: G is 6 x 12 (normal, then
    two tangents per corner); W = G^T M^-1 G has rank 6 (redundant contacts)."""
    corners = [(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0.5, 0.5, -0.5), (-0.5, 0.5, -0.5)]
    dirs = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    G = np.zeros((6, 12))
    for k, rho in enumerate(corners):
        for c, d in enumerate(dirs):
            G[:3, 3 * k + c] = d
            G[3:, 3 * k + c] = np.cross(rho, d)
    return G


@pytest.mark.parametrize("mu", [0.1, 0.5, 1.5])
def test_redundant_corners_give_the_analytic_post_step_velocity(mu):
    """The cube lands (v_n = -2) while sliding at v_t = (0.4, -0.2): the total normal impulse
    is m * 2 = 2 and the slip shrinks by mu * 2 / m, or stops (sticking) when that exceeds it.
    The four normal impulses are not unique (W has rank 6), the velocity is."""
    M = np.array([1.0, 1.0, 1.0, 1 / 6, 1 / 6, 1 / 6])
    G = cube_g()
    vt = np.array([0.4, -0.2])
    v_free = np.array([vt[0], vt[1], -2.0, 0.0, 0.0, 0.0])
    W, q = contact.assemble(M, G, v_free)
    assert np.linalg.matrix_rank(W) == 6
    r = contact.solve(W, q, mu, method="prox", tol=1e-12)
    assert r.success, r.message
    _, err_q = contact_error(W, q, np.full(4, mu), 3, r.impulse)
    assert err_q <= 1e-12
    slip = max(0.0, 1.0 - 2.0 * mu / np.linalg.norm(vt))
    expected = np.array([vt[0] * slip, vt[1] * slip, 0.0, 0.0, 0.0, 0.0])
    v_prox = contact.post_velocity(M, G, v_free, r.impulse)
    np.testing.assert_allclose(v_prox, expected, atol=1e-9)
    assert r.impulse[:, 0].sum() == pytest.approx(2.0, abs=1e-9)
    n = contact.solve(W, q, mu, method="nsgs", tol=1e-12, max_iter=100000)
    assert n.success, n.message
    np.testing.assert_allclose(contact.post_velocity(M, G, v_free, n.impulse), v_prox, atol=1e-8)


def random_problem(seed: int, nc: int, dim: int, mu: float):
    """W = G^T G / 4 (rank-deficient when dim nc > ndof) and q pushing every contact in."""
    rng = np.random.default_rng(seed)
    ndof = 6 * (nc // 4) + 3
    G = rng.standard_normal((ndof, dim * nc))
    W = G.T @ G / 4.0
    q = rng.standard_normal(dim * nc)
    q[::dim] = -np.abs(q[::dim]) - 0.5
    return W, q, np.full(nc, mu)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("dim", [2, 3])
def test_random_problems_against_the_independent_residual(seed, dim):
    W, q, mu = random_problem(seed, 4 + 3 * seed, dim, [0.0, 0.2, 0.5, 1.0, 2.0, 0.3][seed])
    r = contact.solve(W, q, mu, dim=dim, method="prox")
    assert r.success, r.message
    err, err_q = contact_error(W, q, mu, dim, r.impulse)
    # near its rounding level error_q is that rounding, which numpy's sums round otherwise
    assert abs(err_q - r.error_q) <= 1e-3 * err_q + r.error_q_floor
    # the verdict: both halves pass, recomputed here
    assert contact_scaled_error(W, q, mu, dim, r.impulse) <= TOL
    assert err_q <= max(TOL, r.error_q_floor) + r.error_q_floor
    assert abs(err - r.error) <= 1e-3 * err + 1e-15
    if mu[0] == 0.0:
        assert np.abs(r.impulse[:, 1:]).max() == 0.0


@pytest.fixture(scope="module")
def fc_set() -> tuple[Path, bool]:
    """The full Siconos friction-contact set if present (required in CI), else the subset
    shipped in tests/data."""
    return available_dir("siconos-fc")


HARD = ("BoxesStack1-i100000-32.hdf5", "OneObject-i100000-316.hdf5", "OneObject-i100000-499.hdf5")


@pytest.mark.parametrize("name", HARD)
def test_problems_where_nsgs_stalls_are_solved(name):
    p = read_siconos_fc(data_file("siconos-fc", f"{name}.dat"))
    r = contact.solve(p.W, p.q, p.mu, p.dim, method="prox", tol=TOL)
    assert r.success, r.message
    assert r.iterations <= 60
    err, err_q = contact_error(p.W, p.q, p.mu, p.dim, r.impulse)
    assert err_q <= TOL and err <= TOL
    # contrast: plain NSGS sweeps stall within 2000 sweeps only on BoxesStack1, whose stall
    # is the face contacts' drift along W's null directions; the sticking-set solve (the
    # default) ends it in 12 sweeps (Siconos's NSGS: not converged in 10,000).
    # OneObject-i100000-316 stalled while NSGS symmetrised the diagonal blocks of its slightly
    # unsymmetric W; OneObject-i100000-499 while a contact that others act on repeated its
    # normal / tangential passes within a sweep (two passes per sweep solve it; Siconos's NSGS
    # stalls at 1e-3)
    plain = contact.solve(p.W, p.q, p.mu, p.dim, method="nsgs", tol=TOL, max_iter=2000,
                          sticking=False)
    n = contact.solve(p.W, p.q, p.mu, p.dim, method="nsgs", tol=TOL, max_iter=2000)
    if name.startswith("OneObject"):
        assert plain.success and plain.error_q <= TOL, plain.message
        assert max(contact_error(p.W, p.q, p.mu, p.dim, plain.impulse)) <= TOL
    else:
        assert not plain.success and plain.error_q > 10 * TOL
    assert n.success and n.iterations <= 2000, n.message
    assert max(contact_error(p.W, p.q, p.mu, p.dim, n.impulse)) <= TOL


def redundant_planar_problem(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A planar pile, massively redundant: 60 bodies (180 dofs), 200 contacts (400 contact
    rows), each contact on one or two bodies at a random angle and lever arm, diagonal M;
    ``W = G^T M^-1 G`` (rank <= 180, so >= 220 null directions) and ``q = G^T v`` with v
    random and falling, mu = 0.5."""
    rng = np.random.default_rng(seed)
    nb, nc = 60, 200
    G = np.zeros((3 * nb, 2 * nc))
    for i in range(nc):
        a, b = rng.choice(nb, 2, replace=False)
        ang = rng.uniform(0.0, 2.0 * np.pi)
        n = np.array([np.cos(ang), np.sin(ang)])
        arm_a, arm_b = rng.normal(size=2) * 0.5, rng.normal(size=2) * 0.5
        two = rng.random() < 0.7
        for k, d in enumerate((n, np.array([-n[1], n[0]]))):
            G[3 * a : 3 * a + 2, 2 * i + k] = d
            G[3 * a + 2, 2 * i + k] = arm_a[0] * d[1] - arm_a[1] * d[0]
            if two:
                G[3 * b : 3 * b + 2, 2 * i + k] = -d
                G[3 * b + 2, 2 * i + k] = -(arm_b[0] * d[1] - arm_b[1] * d[0])
    minv = np.repeat(1.0 / rng.uniform(0.5, 2.0, nb), 3) * np.tile([1.0, 1.0, 6.0], nb)
    v = rng.normal(size=3 * nb)
    v[1::3] -= 3.0
    return G.T @ (minv[:, None] * G), G.T @ v, np.full(nc, 0.5)


@pytest.mark.parametrize("seed", [2, 3, 4, 5])
def test_massively_redundant_planar_problems_are_finished_by_the_lcp(seed):
    """W exact to rounding (PSD, rank-deficient), yet Newton makes no tenfold progress in 25
    steps on them; measured with the finish disabled, the robust mode stalled at error_q
    2.2e-3 (seed 2), 6.5e-4 (4) and 4.0e-6 (5) and solved seed 3 in 151 steps (NSGS, 20000
    sweeps: 6e-6, 1.9e-8, 1.4e-4, 2.7e-5). The 2D LCP finish (Lemke on the contacts that
    push, grown by those that close: 115 to 131 of the 200) solves all four to error_q
    <= 1.2e-13 after 25 to 42 Newton steps (seed 4 to 8.9e-12 since a round's LCP that the
    first Lemke path does not solve is retried on other paths: 144 contacts, 6 rounds)."""
    W, q, mu = redundant_planar_problem(seed)
    # with 25 Newton steps (no tenfold progress in them) the answer still comes from the
    # finish: at the first stall, or past the budget on the whole problem as one LCP
    short = contact.solve(W, q, mu, 2, method="prox", tol=TOL, max_iter=25)
    assert short.success and "2D LCP finish" in short.message, short.message
    r = contact.solve(W, q, mu, 2, method="prox", tol=TOL)
    assert r.success and "2D LCP finish" in r.message, r.message
    err, err_q = contact_error(W, q, mu, 2, r.impulse)
    assert err_q <= 1e-10 and err <= 1e-10, err_q
    assert abs(err_q - r.error_q) <= 1e-3 * TOL
    assert r.min_normal_impulse >= -1e-12 * r.impulse[:, 0].max()


def test_a_redundant_pile_rounded_to_6_digits_is_reported_unsolved():
    """The same pile with W printed with 6 significant digits (as the FCLib 2D file's): W is
    then indefinite (min eigenvalue -5.8e-5 against 59) and Lemke on the whole 2D LCP
    ray-terminates; the finish is tried, fails on the whole problem, and the answer is
    reported as unsolved (error_q 3.3e-5 after 200 steps), never claimed."""
    W, q, mu = redundant_planar_problem(3)
    W6 = np.array([float(f"{v:.6g}") for v in W.ravel()]).reshape(W.shape)
    assert np.linalg.eigvalsh(W6)[0] < -1e-7 * np.abs(W6).max()
    r = contact.solve(W6, q, mu, 2, method="prox", tol=TOL, max_iter=60)
    assert not r.success and r.status in ("iteration_limit", "numerical_failure")
    assert "LCP finish" not in r.message
    _, err_q = contact_error(W6, q, mu, 2, r.impulse)
    assert err_q > TOL and abs(err_q - r.error_q) <= 1e-6 * err_q


# not run here: RockPile_tob1 (hard, see test_fclib.py) and fc2d_granularflowonwall_02020_00213
# (nc = 2020, read dense here: its FCLib copy, the same W and q, is solved block-sparse by the
# 2D LCP finish in test_fclib.py)
# RockPile: not solved; the 2D flow: its own test; Capsules-i122-1617: its own test in
# tests/python/test_fclib.py
SKIPPED = ("RockPile_tob1", "fc2d_granularflowonwall_02020_00213", "Capsules-i122-1617")


def test_every_local_siconos_problem_is_solved_at_1e_8(fc_set):
    fc_dir, full = fc_set
    solved = 0
    for f in sorted(fc_dir.glob("*.dat")):
        # the one file beyond the 5000 x 5000 densification limit is a global problem
        if f.stem in SKIPPED or f.stem == "gfc2d_granularflowonwall_00230_00206":
            continue
        p = read_siconos_fc(f)
        if not isinstance(p, FrictionContactProblem):
            continue
        r = contact.solve(p.W, p.q, p.mu, p.dim, method="prox", tol=TOL)
        assert r.success, (f.stem, r.message)
        _, err_q = contact_error(p.W, p.q, p.mu, p.dim, r.impulse)
        assert err_q == pytest.approx(r.error_q, rel=1e-6, abs=1e-3 * TOL), f.stem
        # the verdict's measure, recomputed independently (error_q, which adds velocities
        # to impulses, may exceed tol: Rover11035 has 1.5e-8)
        assert contact_scaled_error(p.W, p.q, p.mu, p.dim, r.impulse) <= TOL, f.stem
        solved += 1
    # the full set has 41 such local problems solved here (Capsules-i122-1617 is set aside
    # above), the shipped subset 33 minus those set aside that ship
    assert solved == (41 if full else 33)


def test_warm_start_and_iteration_limit():
    p = read_siconos_fc(data_file("siconos-fc", "BoxesStack1-i100000-32.hdf5.dat"))
    r = contact.solve(p.W, p.q, p.mu, p.dim, method="prox")
    again = contact.solve(p.W, p.q, p.mu, p.dim, method="prox", initial=r.impulse)
    # the warm start is projected on the cones first, which may move it by rounding
    assert again.success and again.iterations <= 1
    np.testing.assert_allclose(again.impulse, r.impulse, atol=1e-9 * np.abs(r.impulse).max())
    # two Newton steps, then the polyhedral LCP on every contact (520 unknowns): each sticks
    # or separates, so the polygon's answer is the disk's
    finished = contact.solve(p.W, p.q, p.mu, p.dim, method="prox", max_iter=2)
    assert finished.success and "polyhedral LCP finish" in finished.message
    assert finished.iterations == 2
    assert contact_scaled_error(p.W, p.q, p.mu, p.dim, finished.impulse) <= TOL
    # where the finish gives no answer that passes (OneObject), the limit is reported as such
    o = read_siconos_fc(data_file("siconos-fc", "OneObject-i100000-499.hdf5.dat"))
    short = contact.solve(o.W, o.q, o.mu, o.dim, method="prox", max_iter=2)
    assert not short.success and short.status == "iteration_limit"
    assert short.iterations == 2 and short.error_q > TOL
    assert "max_iter = 2" in short.message


@pytest.mark.parametrize(
    ("kwargs", "exc", "words"),
    [
        ({"eta": 0.0}, errors.InvalidParameterError, "eta"),
        ({"eta": float("nan")}, errors.InvalidParameterError, "eta"),
        ({"relaxation": 1.5}, errors.InvalidParameterError, "relaxation"),
        ({"facets": 8}, errors.InvalidParameterError, "facets"),
        ({"tol": -1.0}, errors.InvalidParameterError, "tol"),
        ({"max_iter": 0}, errors.InvalidParameterError, "max_iter"),
        ({"initial": [1.0, 2.0]}, errors.ShapeError, "initial"),
    ],
)
def test_input_errors(kwargs, exc, words):
    W, q = seed_problem(3)
    with pytest.raises(exc, match=words):
        contact.solve(W, q, 0.2, method="prox", **kwargs)


def test_eta_belongs_to_prox():
    W, q = seed_problem(3)
    with pytest.raises(errors.InvalidParameterError, match="eta"):
        contact.solve(W, q, 0.2, method="nsgs", eta=1.0)
    r = contact.solve(W, q, 0.2, method="prox", eta=1e-3)
    assert r.success and r.impulse[0, 0] == pytest.approx(6.0)


BOXPILE = ["BoxPile1000-island66.hdf5", "BoxPile1000-island73.hdf5"]


@pytest.mark.parametrize("name", BOXPILE)
def test_landing_islands_of_a_box_pile_are_solved_through_the_lcp_finish(name):
    """Two landing islands of coulomb's 1000-box pile (10 boxes, 66 and 73 contacts, W of
    rank 60): every contact of the answer sticks or separates, NSGS creeps (all contacts
    micro-sliding near 1e-5) and Newton alone stalls near 4e-6. The polyhedral finish on the
    contacts that push (up to 76 of them at 8 directions: more than 500 LCP unknowns) finds
    which separate; the answer is judged here by the independent measures."""
    p = read_fclib(data_file("boxpile", name))
    dense = p.W.toarray()
    r = contact.solve(p.W, p.q, p.mu, dim=3, method="prox", tol=TOL, max_iter=50)
    assert r.success, r.message
    assert "polyhedral LCP finish" in r.message
    assert contact_scaled_error(dense, p.q, p.mu, 3, r.impulse) <= TOL
    assert contact_error(dense, p.q, p.mu, 3, r.impulse)[1] <= TOL
    R = r.impulse.reshape(-1, 3)
    slip = np.linalg.norm(r.velocity.reshape(-1, 3)[:, 1:], axis=1)
    pushing = R[:, 0] > 0
    # the boxes come to rest: no pushing contact slides
    assert slip[pushing].max() <= 1e-9 * np.abs(p.q).max()
    # NSGS's verdict on the same problem is honest whatever it reaches
    n = contact.solve(p.W, p.q, p.mu, dim=3, method="nsgs", tol=TOL, max_iter=500)
    measured = contact_scaled_error(dense, p.q, p.mu, 3, n.impulse)
    assert n.success == (measured <= TOL and n.error_q <= TOL)
