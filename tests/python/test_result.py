"""The result object: dict and attribute access, readable repr, and figures that agree with
their definitions recomputed in numpy."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
from coulomb import lcp
from helpers import lcp_error, planted_psd


@pytest.fixture(scope="module")
def problem():
    rng = np.random.default_rng(42)
    M, q, _, _, _ = planted_psd(rng, 12)
    return M, q


@pytest.fixture(scope="module", params=["lemke", "pgs", "enumerate"])
def result(request, problem):
    M, q = problem
    if request.param == "pgs":
        M = M + np.eye(len(q))  # PGS needs a positive diagonal; make it SPD
    return M, q, lcp.solve(M, q, method=request.param)


def test_is_an_lcp_result(result):
    _, _, r = result
    assert isinstance(r, coulomb.LcpResult)
    assert isinstance(r, coulomb.Result)
    assert isinstance(r, dict)


def test_attribute_and_key_access(result):
    _, _, r = result
    for key in ("z", "w", "success", "status", "message", "error", "pivots", "basis"):
        assert key in r
        assert r[key] is getattr(r, key)
    assert "success" in dir(r)
    with pytest.raises(AttributeError):
        _ = r.no_such_field
    with pytest.raises(KeyError):
        _ = r["no_such_field"]


def test_repr(result):
    _, _, r = result
    text = repr(r)
    assert text.startswith("LcpResult(")
    assert "success" in text and "status" in text
    assert repr(r.status) in text
    assert str(r) == text


def test_w_is_recomputed_from_the_data(result):
    M, q, r = result
    expected = M @ r.z + q
    scale = np.abs(M).max() * np.abs(r.z).max() + np.abs(q).max()
    np.testing.assert_allclose(r.w, expected, rtol=1e-12, atol=1e-12 * scale)


def test_measures_match_their_definitions(result):
    M, q, r = result
    assert r.success is True
    assert r.error == pytest.approx(lcp_error(M, q, r.z), rel=1e-9, abs=1e-15)
    assert r.min_z == pytest.approx(r.z.min(), abs=1e-15)
    assert r.min_w == pytest.approx(r.w.min(), abs=1e-12 * max(1.0, np.abs(q).max()))
    assert r.max_complementarity == pytest.approx(np.abs(r.z * r.w).max(), abs=1e-12)
    # basis: the indices with z_i basic, z_i = 0 elsewhere
    outside = np.setdiff1d(np.arange(len(q)), r.basis)
    if r.status == "solved" and r.pivots:
        np.testing.assert_array_equal(r.z[outside], 0.0)


def test_check_recomputes_the_same_measures(result):
    M, q, r = result
    c = lcp.check(M, q, r.z)
    assert isinstance(c, coulomb.Result)
    for key in ("error", "scaled_error", "min_z", "min_w", "max_complementarity"):
        assert c[key] == pytest.approx(r[key], rel=1e-12, abs=1e-300), key
    np.testing.assert_allclose(c.w, r.w, rtol=1e-12, atol=1e-12 * np.abs(q).max())


def test_check_on_a_hand_made_answer():
    # M = I, q = (-1, 2): z = (1, 0) is exact; z = (0.5, 0) misses by 0.5 in row 1.
    M = np.eye(2)
    q = np.array([-1.0, 2.0])
    assert lcp.check(M, q, [1.0, 0.0]).error == 0.0
    c = lcp.check(M, q, [0.5, 0.0])
    np.testing.assert_allclose(c.w, [-0.5, 2.0])
    assert c.error == pytest.approx(0.5 / np.sqrt(5.0), rel=1e-14)
    assert c.min_w == pytest.approx(-0.5)


def test_result_is_a_plain_dict_copy():
    r = lcp.solve([[2.0]], [-6.0])
    d = dict(r)
    assert d["status"] == "solved"
    assert d["z"][0] == pytest.approx(3.0)
