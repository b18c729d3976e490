"""coulomb.contact.solve(method="lemke"): the seed's inelastic step by the polyhedral-cone LCP
(exact in 2D), sticking, facet convergence against the exact disk, and bad facets."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import contact, errors


def seed_problem(dim: int, mu: float):
    """m = 2, e = 0, v_n^- = -3, v_t^- = 1: W = I / m, q = (-3, 1[, 0])."""
    return np.eye(dim) / 2.0, np.array([-3.0, 1.0, 0.0][:dim]), mu


@pytest.mark.parametrize("dim", [2, 3])
def test_seed_inelastic_step_slides(dim):
    W, q, mu = seed_problem(dim, 0.2)
    r = contact.solve(W, q, mu, dim=dim, method="lemke")
    assert r.success and r.status == "solved", r.message
    assert "Lemke" in r.message and r.iterations > 0
    expected_r = [6.0, -1.2, 0.0][:dim]
    expected_u = [0.0, 0.4, 0.0][:dim]
    np.testing.assert_allclose(r.impulse[0], expected_r, atol=1e-10)
    np.testing.assert_allclose(r.velocity[0], expected_u, atol=1e-10)
    assert 0.5 * 2.0 * float(r.velocity[0] @ r.velocity[0]) == pytest.approx(0.16, abs=1e-10)
    d = contact.solve(W, q, mu, dim=dim, method="nsgs")
    np.testing.assert_allclose(r.impulse, d.impulse, atol=1e-10)
    np.testing.assert_allclose(r.velocity, d.velocity, atol=1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_sticking(dim):
    W, q, mu = seed_problem(dim, 0.6)
    r = contact.solve(W, q, mu, dim=dim, method="lemke")
    assert r.success, r.message
    np.testing.assert_allclose(r.velocity[0], 0.0, atol=1e-10)
    assert r.impulse[0, 1] == pytest.approx(-2.0, abs=1e-10)


def test_oblique_slip_approaches_the_disk():
    W, q = np.eye(3) / 2.0, np.array([-3.0, 0.6, 0.8])
    disk = contact.solve(W, q, 0.2, dim=3, tol=1e-12)
    np.testing.assert_allclose(disk.velocity[0], [0.0, 0.24, 0.32], atol=1e-10)
    errs = []
    for facets in (4, 8, 16, 32, 64):
        r = contact.solve(W, q, 0.2, dim=3, method="lemke", facets=facets)
        assert r.success, r.message
        errs.append(np.linalg.norm(r.velocity[0] - disk.velocity[0]) / 0.4)
    assert errs[-1] < 1e-2 and max(errs[2:]) < errs[0], errs
    # the disk measure reflects the facet error and shrinks with it
    coarse = contact.solve(W, q, 0.2, dim=3, method="lemke", facets=4)
    fine = contact.solve(W, q, 0.2, dim=3, method="lemke", facets=64)
    assert fine.error < coarse.error


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"dim": 3, "facets": 2}, "facets must be even and at least 4"),
        ({"dim": 3, "facets": 7}, "facets must be even and at least 4"),
        ({"dim": 2, "facets": 3}, "facets must be 2 in 2D"),
        ({"dim": 2, "facets": 4}, "facets must be 2 in 2D"),
        ({"dim": 3, "facets": 8.0}, "integer"),
        ({"dim": 3, "initial": np.zeros(3)}, "nsgs"),
        ({"dim": 3, "relaxation": 1.5}, "nsgs"),
    ],
)
def test_bad_options_are_refused(kwargs, words):
    dim = kwargs["dim"]
    W, q, mu = seed_problem(dim, 0.2)
    with pytest.raises(errors.InvalidParameterError) as info:
        contact.solve(W, q, mu, method="lemke", **kwargs)
    assert words in str(info.value)


def test_facets_is_for_lemke_only_and_checked_by_the_core():
    from coulomb import _core

    W, q, mu = seed_problem(3, 0.2)
    with pytest.raises(errors.InvalidParameterError, match="lemke"):
        contact.solve(W, q, mu, dim=3, facets=8)
    with pytest.raises(errors.InvalidParameterError, match="facets"):
        _core.contact_solve(W, q, np.array([0.2]), 3, "lemke", 1e-8, facets=5)


def test_pivot_limit_is_reported():
    W, q, mu = seed_problem(3, 0.2)
    r = contact.solve(W, q, mu, dim=3, method="lemke", max_iter=1)
    assert not r.success and r.status == "iteration_limit" and "pivot" in r.message
