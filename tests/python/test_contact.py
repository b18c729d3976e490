"""coulomb.contact.solve: the seed's contact step, sticking, the reported error against an
independent numpy residual, warm start, and input errors refused before any work."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from coulomb import contact, errors
from helpers import GIL_RELEASED, contact_error, contact_scaled_error, count_during


def seed_problem(dim: int, mu: float):
    """m = 2, e = 0, v_n^- = -3, v_t^- = 1: W = I / m, q = (-3, 1[, 0])."""
    W = np.eye(dim) / 2.0
    q = np.array([-3.0, 1.0, 0.0][:dim])
    return W, q, mu


def kinetic_energy(v, m=2.0):
    return 0.5 * m * float(np.dot(v, v))


def random_problem(seed: int, nc: int, dim: int = 3, mu: float = 0.3):
    """W = G^T G / m for random contact frames on 6 * nc // 4 + 3 degrees of freedom, and a
    free velocity pushing every contact into the surface with some slip."""
    rng = np.random.default_rng(seed)
    ndof = 6 * (nc // 4) + 3
    G = rng.standard_normal((ndof, dim * nc))
    W = G.T @ G / 4.0
    q = rng.standard_normal(dim * nc)
    q[::dim] = -np.abs(q[::dim]) - 0.5
    return W, q, np.full(nc, mu)


@pytest.mark.parametrize("dim", [2, 3])
def test_seed_inelastic_step_slides(dim):
    W, q, mu = seed_problem(dim, 0.2)
    r = contact.solve(W, q, mu, dim=dim)
    assert isinstance(r, contact.ContactResult)
    assert r.success and r.status == "solved"
    assert r.impulse.shape == (1, dim) and r.velocity.shape == (1, dim)
    P, u = r.impulse[0], r.velocity[0]
    np.testing.assert_allclose(P[:2], [6.0, -1.2], atol=1e-12)
    np.testing.assert_allclose(u[:2], [0.0, 0.4], atol=1e-12)
    if dim == 3:
        assert abs(P[2]) < 1e-12 and abs(u[2]) < 1e-12
    assert kinetic_energy(q) == pytest.approx(10.0)
    assert kinetic_energy(u) == pytest.approx(0.16, abs=1e-12)
    # sliding: the friction impulse is on the cone boundary and opposes the slip
    assert np.linalg.norm(P[1:]) == pytest.approx(0.2 * P[0], abs=1e-12)
    assert np.dot(P[1:], u[1:]) < 0
    assert r.error <= 1e-14 and r.error_q <= 1e-14
    assert r.min_normal_impulse == pytest.approx(6.0)
    assert r.cone_violation <= 1e-12 and r.dissipation_violation == 0.0
    assert r.max_complementarity <= 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_seed_sticks_with_high_friction(dim):
    W, q, mu = seed_problem(dim, 0.6)
    r = contact.solve(W, q, mu, dim=dim)
    assert r.success
    P, u = r.impulse[0], r.velocity[0]
    np.testing.assert_allclose(u, 0.0, atol=1e-12)
    np.testing.assert_allclose(P[:2], [6.0, -2.0], atol=1e-12)
    assert np.linalg.norm(P[1:]) < 0.6 * P[0]
    assert kinetic_energy(u) == pytest.approx(0.0, abs=1e-20)


def test_separating_contact_has_no_impulse():
    r = contact.solve(np.eye(3) / 2, [1.0, 5.0, -2.0], 0.5)
    assert r.success
    np.testing.assert_array_equal(r.impulse, 0.0)
    np.testing.assert_allclose(r.velocity[0], [1.0, 5.0, -2.0])


def test_oblique_slip_in_3d_opposes_the_slip_direction():
    # slip along (3, 4) / 5 in the tangent plane: the friction impulse points exactly against it
    r = contact.solve(np.eye(3) / 2, [-3.0, 0.6, 0.8], 0.2)
    P, u = r.impulse[0], r.velocity[0]
    assert r.success
    np.testing.assert_allclose(P, [6.0, -0.72, -0.96], atol=1e-12)
    np.testing.assert_allclose(u, [0.0, 0.24, 0.32], atol=1e-12)


@pytest.mark.parametrize(("seed", "dim"), [(0, 3), (1, 3), (2, 2), (3, 2)])
def test_reported_error_matches_independent_residual(seed, dim):
    W, q, mu = random_problem(seed, nc=8, dim=dim)
    for max_iter in (1, 3, 1000):
        r = contact.solve(W, q, mu, dim=dim, max_iter=max_iter, tol=1e-10)
        err, err_q = contact_error(W, q, mu, dim, r.impulse)
        assert r.error == pytest.approx(err, rel=1e-9, abs=1e-15)
        assert r.error_q == pytest.approx(err_q, rel=1e-9, abs=1e-15)
        np.testing.assert_allclose(r.velocity.ravel(), W @ r.impulse.ravel() + q, atol=1e-12)
        assert r.scaled_error == pytest.approx(
            contact_scaled_error(W, q, mu, dim, r.impulse), rel=1e-9, abs=1e-15
        )
        # the one rule: success means the unit-consistent measure passes tol and the
        # literature's error_q passes max(tol, its rounding floor)
        assert r.success == (r.scaled_error <= 1e-10
                             and err_q <= max(1e-10, r.error_q_floor) * (1 + 1e-9))
    assert r.success, r.message
    # at the solution every contact pushes, stays in its cone and dissipates
    assert r.min_normal_impulse >= 0.0
    assert r.cone_violation <= 1e-9 * np.abs(r.impulse).max()


def test_iteration_limit_is_reported_honestly():
    W, q, mu = random_problem(0, nc=8)
    r = contact.solve(W, q, mu, max_iter=1, tol=1e-12)
    assert not r.success
    assert r.status == "iteration_limit"
    assert r.iterations == 1
    assert r.error > 1e-12
    assert r.error == pytest.approx(contact_error(W, q, mu, 3, r.impulse)[0], rel=1e-9)


def test_warm_start_from_the_answer_converges_at_once():
    W, q, mu = random_problem(1, nc=8)
    cold = contact.solve(W, q, mu)
    assert cold.success and cold.iterations > 1
    warm = contact.solve(W, q, mu, initial=cold.impulse)
    flat = contact.solve(W, q, mu, initial=cold.impulse.ravel())
    assert warm.success and warm.iterations <= 2
    assert flat.iterations == warm.iterations
    np.testing.assert_allclose(warm.impulse, cold.impulse, atol=1e-6 * np.abs(cold.impulse).max())


def test_sparse_w_and_per_contact_mu():
    W, q, _ = random_problem(2, nc=6)
    mu = np.linspace(0.0, 1.0, 6)
    dense = contact.solve(W, q, mu)
    sparse = contact.solve(sp.csr_matrix(W), list(q), mu)
    assert dense.success
    np.testing.assert_array_equal(dense.impulse, sparse.impulse)
    # the frictionless contact carries no tangential impulse
    np.testing.assert_array_equal(dense.impulse[0, 1:], 0.0)


def test_relaxation_changes_the_path_not_the_answer():
    W, q, mu = random_problem(3, nc=8)
    a = contact.solve(W, q, mu)
    b = contact.solve(W, q, mu, relaxation=0.7, max_iter=5000)
    assert a.success and b.success
    assert a.iterations != b.iterations
    np.testing.assert_allclose(a.velocity, b.velocity, atol=1e-5 * np.abs(q).max())


@pytest.mark.parametrize(
    ("kwargs", "exc", "words"),
    [
        ({"W": np.eye(4)}, errors.ShapeError, "W must have shape (3, 3)"),
        ({"W": np.ones(3)}, errors.ShapeError, "2-D"),
        ({"q": [-3.0, 1.0]}, errors.ShapeError, "multiple of dim"),
        ({"mu": [0.2, 0.3]}, errors.ShapeError, "mu has 2 entries"),
        ({"mu": -0.1}, errors.InvalidParameterError, "mu[0]"),
        ({"mu": np.nan}, errors.NonFiniteError, "mu"),
        ({"q": [np.nan, 1.0, 0.0]}, errors.NonFiniteError, "q"),
        ({"W": np.full((3, 3), np.inf)}, errors.NonFiniteError, "W"),
        ({"dim": 4}, errors.InvalidParameterError, "dim must be 2"),
        ({"dim": 3.0}, errors.InvalidParameterError, "dim must be 2"),
        ({"method": "lemke", "facets": 3}, errors.InvalidParameterError, "facets"),
        ({"method": "pgs"}, errors.InvalidParameterError, "'nsgs'"),
        ({"tol": 0.0}, errors.InvalidParameterError, "tol"),
        ({"max_iter": 0}, errors.InvalidParameterError, "max_iter"),
        ({"relaxation": 2.0}, errors.InvalidParameterError, "relaxation"),
        ({"initial": np.zeros((2, 3))}, errors.ShapeError, "initial"),
        ({"initial": [np.inf, 0.0, 0.0]}, errors.NonFiniteError, "initial"),
        ({"W": np.eye(3) * 1j}, errors.InvalidInputError, "real"),
    ],
)
def test_input_errors_are_specific(kwargs, exc, words):
    args = {"W": np.eye(3) / 2, "q": [-3.0, 1.0, 0.0], "mu": 0.2, "dim": 3}
    args.update(kwargs)
    with pytest.raises(exc) as info:
        contact.solve(**args)
    assert words in str(info.value)
    assert isinstance(info.value, ValueError)


def test_core_refuses_unknown_method_and_ragged_w():
    from coulomb import _core

    with pytest.raises(errors.InvalidParameterError, match="lemke"):
        _core.contact_solve(np.eye(3), np.zeros(3), np.zeros(1), 3, "pgs", 1e-8)
    # "lemke" is a method now
    out = _core.contact_solve(np.eye(3), np.zeros(3), np.zeros(1), 3, "lemke", 1e-8)
    assert out["success"]
    with pytest.raises(errors.ShapeError):
        _core.contact_solve(np.eye(3)[:2], np.zeros(3), np.zeros(1), 3, "nsgs", 1e-8)
    with pytest.raises(errors.ShapeError):
        _core.contact_solve(np.eye(3), np.zeros(3), np.zeros(2), 3, "nsgs", 1e-8)


def test_no_contacts():
    r = contact.solve(np.zeros((0, 0)), np.zeros(0), 0.3)
    assert r.success and r.impulse.shape == (0, 3)


def test_large_solve_releases_the_gil():
    W, q, mu = random_problem(4, nc=200)
    # a tolerance no iterate reaches: the sweeps run to max_iter
    r, count = count_during(lambda: contact.solve(W, q, mu, tol=1e-300, max_iter=300))
    assert r.error <= 1e-10  # converged long before the 300 sweeps end
    # see helpers.count_during: a GIL-holding call lets the main thread count to at most ~600
    assert count > GIL_RELEASED, (count, r.solve_time)
