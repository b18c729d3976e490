"""coulomb.contact.assemble and post_velocity against a numpy oracle (np.linalg.solve):
diagonal, block-diagonal (rigid bodies), non-diagonal dense and sparse mass matrices; a mass
matrix that is not positive definite or not symmetric is refused, naming M."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
import scipy.sparse as sp
from coulomb import contact, errors
from hypothesis import given, settings
from hypothesis import strategies as st


def oracle(M, G, v_free, extra=None):
    Md = M.toarray() if sp.issparse(M) else (np.diag(M) if np.ndim(M) == 1 else M)
    Gd = G.toarray() if sp.issparse(G) else G
    W = Gd.T @ np.linalg.solve(Md, Gd)
    q = Gd.T @ v_free + (0 if extra is None else extra)
    return W, q, Md, Gd


def spd(rng, n, shift=0.5):
    A = rng.standard_normal((n, n))
    return A @ A.T + shift * np.eye(n)


def block_diagonal(rng, nbodies, size=6):
    M = np.zeros((nbodies * size, nbodies * size))
    for b in range(nbodies):
        s = slice(b * size, (b + 1) * size)
        M[s, s] = spd(rng, size)
    return M


def check(M, G, v_free, extra=None, rtol=1e-11):
    W, q = contact.assemble(M, G, v_free, extra=extra)
    Wo, qo, Md, Gd = oracle(M, G, v_free, extra)
    assert W.shape == Wo.shape and np.array_equal(W, W.T)
    assert np.abs(W - Wo).max() <= rtol * np.abs(Wo).max()
    assert np.abs(q - qo).max() <= rtol * max(np.abs(qo).max(), 1.0)
    r = np.random.default_rng(1).standard_normal(Gd.shape[1])
    v = contact.post_velocity(M, G, v_free, r)
    vo = v_free + np.linalg.solve(Md, Gd @ r)
    assert np.abs(v - vo).max() <= rtol * np.abs(vo).max()


def test_diagonal_mass_as_a_vector_and_as_a_matrix():
    rng = np.random.default_rng(0)
    m = 0.5 + rng.random(9)
    G = rng.standard_normal((9, 6))
    v = rng.standard_normal(9)
    check(m, G, v)
    check(np.diag(m), G, v, extra=rng.standard_normal(6))


def test_block_diagonal_rigid_bodies():
    rng = np.random.default_rng(2)
    M = block_diagonal(rng, 5)
    G = rng.standard_normal((30, 12))
    G[np.abs(G) < 0.7] = 0.0  # sparse contact directions
    check(M, G, rng.standard_normal(30))
    check(sp.csr_matrix(M), sp.csc_matrix(G), rng.standard_normal(30))


def test_non_diagonal_mass_dense_and_beyond_the_block_limit():
    rng = np.random.default_rng(3)
    # one coupled 40-dof block (dense Cholesky) and one of 300 dofs (faer's sparse Cholesky)
    for n in (40, 300):
        M = spd(rng, n, shift=1.0)
        G = rng.standard_normal((n, 9))
        check(M, G, rng.standard_normal(n), rtol=1e-9)
    # a banded (FEM-like) sparse M of 400 dofs
    n = 400
    main = 4.0 + rng.random(n)
    off = -rng.random(n - 1)
    M = sp.diags([off, main, off], [-1, 0, 1], format="csr")
    G = sp.random(n, 15, density=0.05, random_state=4, format="csr")
    check(M, G, rng.standard_normal(n), rtol=1e-10)


def test_force_instead_of_free_velocity():
    rng = np.random.default_rng(5)
    M = block_diagonal(rng, 3)
    G = rng.standard_normal((18, 6))
    f = rng.standard_normal(18)
    w = rng.standard_normal(6)
    _, q = contact.assemble(M, G, force=f, extra=w)
    qo = G.T @ np.linalg.solve(M, f) + w
    assert np.abs(q - qo).max() <= 1e-11 * np.abs(qo).max()


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    nbodies=st.integers(1, 4),
    ncols=st.integers(1, 9),
    seed=st.integers(0, 2**32 - 1),
)
def test_block_diagonal_property(nbodies, ncols, seed):
    rng = np.random.default_rng(seed)
    M = block_diagonal(rng, nbodies, size=int(rng.integers(1, 7)))
    G = rng.standard_normal((M.shape[0], ncols))
    check(M, G, rng.standard_normal(M.shape[0]), rtol=1e-8)


def test_mass_matrix_errors_name_m():
    G = np.eye(3)
    v = np.zeros(3)
    with pytest.raises(errors.InvalidParameterError, match="mass matrix M is not positive"):
        contact.assemble(np.diag([1.0, -1.0, 1.0]), G, v)
    indefinite = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(errors.InvalidParameterError, match="mass matrix M is not positive"):
        contact.assemble(indefinite, G, v)
    singular = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(errors.InvalidParameterError, match="mass matrix M is not positive"):
        contact.assemble(singular, G, v)
    with pytest.raises(errors.InvalidParameterError, match="mass matrix M must be symmetric"):
        contact.assemble(np.triu(np.ones((3, 3))) + 2 * np.eye(3), G, v)
    # beyond the dense-block limit the sparse Cholesky refuses it too
    n = 300
    big = np.eye(n)
    big[0, 1] = big[1, 0] = 2.0
    big[n - 1, 0] = big[0, n - 1] = 1e-3
    with pytest.raises(errors.InvalidParameterError, match="mass matrix M is not positive"):
        contact.assemble(big, np.eye(n)[:, :3], np.zeros(n))


def test_shape_and_value_errors():
    M, G, v = np.eye(3), np.eye(3)[:, :2], np.zeros(3)
    with pytest.raises(errors.ShapeError):
        contact.assemble(np.eye(4), G, v)
    with pytest.raises(errors.ShapeError):
        contact.assemble(np.ones((3, 4)), G, v)
    with pytest.raises(errors.ShapeError):
        contact.assemble(M, G, np.zeros(2))
    with pytest.raises(errors.ShapeError):
        contact.assemble(M, G, v, extra=np.zeros(3))
    with pytest.raises(errors.NonFiniteError):
        contact.assemble(M, G, np.array([0.0, np.nan, 0.0]))
    with pytest.raises(errors.NonFiniteError):
        contact.assemble(M, np.full((3, 2), np.inf), v)
    with pytest.raises(errors.InvalidParameterError, match="exactly one"):
        contact.assemble(M, G)
    with pytest.raises(errors.InvalidParameterError, match="exactly one"):
        contact.assemble(M, G, v, force=v)
    with pytest.raises(errors.ShapeError):
        contact.post_velocity(M, G, v, np.zeros(3))


def test_a_dense_w_over_the_memory_budget_is_refused():
    old = coulomb.memory_budget()
    try:
        coulomb.set_memory_budget(2**20)
        # 400 contact components: W holds 400^2 * 8 = 1.28 MB > 1 MiB; 300 fit (0.72 MB)
        with pytest.raises(errors.ProblemTooLargeError, match="dense W"):
            contact.assemble(np.ones(2), sp.csr_matrix((2, 400)), np.zeros(2))
        W, q = contact.assemble(np.ones(2), sp.csr_matrix((2, 300)), np.zeros(2))
        assert W.shape == (300, 300) and not W.any() and not q.any()
    finally:
        coulomb.set_memory_budget(old)
    assert coulomb.memory_budget() == old
