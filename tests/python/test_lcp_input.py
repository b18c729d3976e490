"""Bad input is refused with the specific exception class, before any work; good input in
any array layout gives the same answer."""

from __future__ import annotations

import numpy as np
import pytest
from coulomb import errors, lcp
from coulomb.io import read_siconos_lcp

EYE = np.eye(3)
Q = -np.ones(3)


def nan_at(a, idx, value=np.nan):
    a = np.array(a, dtype=float)
    a[idx] = value
    return a


BAD_INPUT = {
    "non-square M": (errors.ShapeError, lambda: lcp.solve(np.ones((2, 3)), [1.0, 1.0])),
    "q length mismatch": (errors.ShapeError, lambda: lcp.solve(EYE, [1.0, 1.0])),
    "1-D M": (errors.ShapeError, lambda: lcp.solve([1.0, 2.0, 3.0], Q)),
    "3-D M": (errors.ShapeError, lambda: lcp.solve(np.ones((1, 1, 1)), [1.0])),
    "2-D q": (errors.ShapeError, lambda: lcp.solve(EYE, np.ones((3, 1)))),
    "NaN in M": (errors.NonFiniteError, lambda: lcp.solve(nan_at(EYE, (2, 1)), Q)),
    "inf in M": (errors.NonFiniteError, lambda: lcp.solve(nan_at(EYE, (0, 0), np.inf), Q)),
    "NaN in q": (errors.NonFiniteError, lambda: lcp.solve(EYE, nan_at(Q, 1))),
    "-inf in q": (errors.NonFiniteError, lambda: lcp.solve(EYE, nan_at(Q, 2, -np.inf))),
    "complex M": (errors.InvalidInputError, lambda: lcp.solve(EYE.astype(complex), Q)),
    "complex q": (errors.InvalidInputError, lambda: lcp.solve(EYE, Q + 0j)),
    "string M": (errors.InvalidInputError, lambda: lcp.solve([["a"]], [1.0])),
    "string q": (errors.InvalidInputError, lambda: lcp.solve([[1.0]], ["x"])),
    "unknown method": (errors.InvalidParameterError, lambda: lcp.solve(EYE, Q, "simplex")),
    "tol = 0": (errors.InvalidParameterError, lambda: lcp.solve(EYE, Q, tol=0.0)),
    "tol < 0": (errors.InvalidParameterError, lambda: lcp.solve(EYE, Q, tol=-1e-9)),
    "tol NaN": (errors.InvalidParameterError, lambda: lcp.solve(EYE, Q, tol=np.nan)),
    "negative covering vector": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, covering_vector=[1.0, -1.0, 1.0]),
    ),
    "zero covering vector entry": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, covering_vector=[1.0, 0.0, 1.0]),
    ),
    "covering vector length": (
        errors.ShapeError,
        lambda: lcp.solve(EYE, Q, covering_vector=[1.0, 1.0]),
    ),
    "warm_start index too large": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, warm_start=[0, 3]),
    ),
    "warm_start index negative": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, warm_start=[-1]),
    ),
    "warm_start mask length": (
        errors.ShapeError,
        lambda: lcp.solve(EYE, Q, warm_start=np.array([True, False])),
    ),
    "enumerate n = 16": (
        errors.ProblemTooLargeError,
        lambda: lcp.solve(np.eye(16), -np.ones(16), method="enumerate"),
    ),
    "PGS zero diagonal": (
        errors.InvalidParameterError,
        lambda: lcp.solve(np.diag([1.0, 0.0, 1.0]), Q, method="pgs"),
    ),
    "PGS negative diagonal": (
        errors.InvalidParameterError,
        lambda: lcp.solve(np.diag([1.0, -1.0, 1.0]), Q, method="pgs"),
    ),
    "relaxation 2.5": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, method="pgs", relaxation=2.5),
    ),
    "relaxation 0": (
        errors.InvalidParameterError,
        lambda: lcp.solve(EYE, Q, method="pgs", relaxation=0.0),
    ),
    "max_pivots 0": (errors.InvalidParameterError, lambda: lcp.solve(EYE, Q, max_pivots=0)),
    "PGS initial length": (
        errors.ShapeError,
        lambda: lcp.solve(EYE, Q, method="pgs", initial=[1.0, 1.0]),
    ),
}


@pytest.mark.parametrize("case", BAD_INPUT)
def test_bad_input_raises_the_specific_error(case):
    exc, call = BAD_INPUT[case]
    with pytest.raises(exc) as info:
        call()
    # exactly that class (or a subclass of it), and always a ValueError for callers
    assert isinstance(info.value, ValueError)
    assert isinstance(info.value, errors.CoulombError)
    assert str(info.value)  # a message for a person


def test_input_error_classes_are_distinct():
    # a shape error is not reported as a non-finite one, and so on
    with pytest.raises(errors.ShapeError) as info:
        lcp.solve(np.ones((2, 3)), [np.nan, 1.0])
    assert not isinstance(info.value, errors.NonFiniteError)
    with pytest.raises(errors.NonFiniteError) as info:
        lcp.solve(EYE, nan_at(Q, 0))
    assert not isinstance(info.value, (errors.ShapeError, errors.InvalidParameterError))


@pytest.mark.parametrize(
    "cls",
    [
        errors.InvalidInputError,
        errors.ShapeError,
        errors.NonFiniteError,
        errors.InvalidParameterError,
        errors.ProblemTooLargeError,
        errors.ProblemFormatError,
        errors.SettingsConflictError,
    ],
)
def test_error_hierarchy(cls):
    assert issubclass(cls, ValueError)
    assert issubclass(cls, errors.CoulombError)


def test_internal_error_is_a_coulomb_error():
    # documented as a RuntimeError (a bug, not bad input)
    assert issubclass(errors.InternalError, errors.CoulombError)
    assert issubclass(errors.InternalError, RuntimeError)
    assert set(errors.__all__) == {
        "ArgumentTypeError",
        "CoulombError",
        "InternalError",
        "InvalidInputError",
        "InvalidParameterError",
        "NonFiniteError",
        "ProblemFormatError",
        "ProblemTooLargeError",
        "SettingsConflictError",
        "ShapeError",
    }


def test_enumerate_at_the_limit_is_allowed():
    # n = 15 is the documented maximum: diag(1..15) z = 1 has z_i = 1 / i
    d = np.arange(1.0, 16.0)
    r = lcp.solve(np.diag(d), -np.ones(15), method="enumerate")
    assert r.success is True
    np.testing.assert_allclose(r.solutions, [1.0 / d], rtol=1e-14)


def test_ints_and_lists_are_converted():
    r = lcp.solve([[2]], [-6])
    assert r.z.dtype == np.float64
    assert r.z[0] == pytest.approx(3.0, abs=1e-12)
    r = lcp.solve(np.array([[2, 0], [0, 4]], dtype=np.int32), (-6, -8))
    np.testing.assert_allclose(r.z, [3.0, 2.0], rtol=1e-14)
    r = lcp.solve(np.array([[2.0]], dtype=np.float32), np.array([-6.0], dtype=np.float32))
    assert r.z[0] == pytest.approx(3.0, abs=1e-6)


def layouts_problem():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((6, 6))
    M = A @ A.T + np.eye(6)
    q = rng.standard_normal(6)
    return M, q


def test_array_layouts_give_the_same_answer():
    M, q = layouts_problem()
    ref = lcp.solve(M, q)
    assert ref.success is True
    big = np.zeros((12, 12))
    big[::2, ::2] = M
    qbig = np.zeros(12)
    qbig[::2] = q
    variants = {
        "Fortran": (np.asfortranarray(M), q),
        "transposed view": (np.ascontiguousarray(M.T).T, q),
        "strided": (big[::2, ::2], qbig[::2]),
        "reversed q view": (M, q[::-1].copy()[::-1]),
        "lists": (M.tolist(), q.tolist()),
    }
    for name, (Mv, qv) in variants.items():
        r = lcp.solve(Mv, qv)
        assert r.success is True, name
        np.testing.assert_allclose(r.z, ref.z, rtol=1e-13, atol=0, err_msg=name)


def test_scipy_sparse_is_densified():
    sparse = pytest.importorskip("scipy.sparse")
    M, q = layouts_problem()
    r = lcp.solve(sparse.csr_matrix(M), q)
    np.testing.assert_allclose(r.z, lcp.solve(M, q).z, rtol=1e-13, atol=0)


def test_inputs_are_not_modified():
    M, q = layouts_problem()
    M0, q0 = M.copy(), q.copy()
    for method in ("lemke", "pgs", "enumerate"):
        lcp.solve(M, q, method=method)
    np.testing.assert_array_equal(M, M0)
    np.testing.assert_array_equal(q, q0)


def test_check_validates_too():
    with pytest.raises(errors.ShapeError):
        lcp.check(EYE, Q, [1.0, 2.0])
    with pytest.raises(errors.NonFiniteError):
        lcp.check(EYE, Q, [1.0, np.nan, 0.0])


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_siconos_lcp(tmp_path / "does_not_exist.dat")


MALFORMED = {
    "garbage": "hello world\n",
    "empty": "",
    "truncated q": "2\n0\n2\n2\n2 2\n1 0 0 1\n-1\n",
    "unknown storage": "2\n7\n2\n2\n2 2\n1 0 0 1\n-1 -1\n",
    "size mismatch": "3\n0\n2\n2\n2 2\n1 0 0 1\n-1 -1\n",
    "non-finite entry": "2\n0\n2\n2\n2 2\n1 0 0 nan\n-1 -1\n",
    "word in matrix": "2\n0\n2\n2\n2 2\n1 0 x 1\n-1 -1\n",
}


@pytest.mark.parametrize("case", MALFORMED)
def test_malformed_file(tmp_path, case):
    path = tmp_path / "lcp_bad.dat"
    path.write_text(MALFORMED[case])
    with pytest.raises(errors.ProblemFormatError) as info:
        read_siconos_lcp(path)
    assert "lcp_bad.dat" in str(info.value)  # the message names the file


def test_well_formed_file_is_column_major(tmp_path):
    path = tmp_path / "lcp_ok.dat"
    path.write_text("2\n0\n2\n2\n2 2\n1 2\n3 4\n-1 -2\ntrailing comment is ignored\n")
    p = read_siconos_lcp(path)
    assert p.name == "lcp_ok"
    assert p.n == 2
    np.testing.assert_array_equal(p.M, [[1.0, 3.0], [2.0, 4.0]])
    np.testing.assert_array_equal(p.q, [-1.0, -2.0])


@pytest.mark.parametrize("n", [1, 2, 5])
def test_check_refuses_a_z_of_the_wrong_length_or_with_nan(n):
    M, q = np.eye(n), -np.ones(n)
    for bad in (np.ones(n + 1), np.ones(max(n - 1, 0))):
        with pytest.raises(errors.ShapeError, match=f"z has length {bad.size}, expected {n}"):
            lcp.check(M, q, bad)
    with pytest.raises(errors.NonFiniteError, match="z"):
        lcp.check(M, q, nan_at(np.ones(n), n - 1))
    # the right length gives the measures of z = 1: w = 0, an exact solution
    assert lcp.check(M, q, np.ones(n)).error == 0.0


@pytest.mark.parametrize(("M", "q", "word"), [
    (np.eye(3), np.ones(2), "q"),          # q does not match M
    (np.ones((2, 3)), np.ones(2), "M"),    # M not square
    (np.eye(2), np.ones(3), "q"),
])
def test_lcp_shapes_that_do_not_fit_are_refused_by_the_core(M, q, word):
    # the Python wrapper leaves this check to the core, which makes it before any work
    with pytest.raises(errors.ShapeError, match=word):
        lcp.solve(M, q)
    with pytest.raises(errors.ShapeError, match=word):
        lcp.solve(M, q, "pgs")
