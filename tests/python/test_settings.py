"""Settings objects (coulomb.settings): the same answers as the keywords they stand for, a
specific error when a setting is given twice, and fields checked when the object is made."""

from __future__ import annotations

import dataclasses

import coulomb
import numpy as np
import pytest
from coulomb import (
    LemkeSettings,
    NSGSSettings,
    PGSSettings,
    PolyhedralSettings,
    ProxSettings,
    StepSettings,
)
from coulomb.errors import ArgumentTypeError, InvalidParameterError, SettingsConflictError

RNG = np.random.default_rng(7)
A = RNG.standard_normal((6, 6))
W3 = A @ A.T + 0.1 * np.eye(6)  # two 3D contacts
Q3 = np.array([-1.0, 0.3, -0.2, -0.5, -0.4, 0.1])
M = W3 + 0.5 * np.eye(6)


@pytest.mark.parametrize(("settings", "keywords"), [
    (NSGSSettings(tol=1e-10, max_iter=500, relaxation=1.2, order="symmetric"),
     {"method": "nsgs", "tol": 1e-10, "max_iter": 500, "relaxation": 1.2, "order": "symmetric"}),
    (PolyhedralSettings(tol=1e-9, facets=16), {"method": "lemke", "tol": 1e-9, "facets": 16}),
    (ProxSettings(tol=1e-10, max_iter=50, eta=1.0),
     {"method": "prox", "tol": 1e-10, "max_iter": 50, "eta": 1.0}),
])
def test_contact_settings_give_the_keywords_answer(settings, keywords) -> None:
    by_object = coulomb.contact.solve(W3, Q3, 0.4, dim=3, settings=settings)
    by_keywords = coulomb.contact.solve(W3, Q3, 0.4, dim=3, **keywords)
    assert by_object.success and by_object.status == by_keywords.status
    np.testing.assert_array_equal(by_object.impulse, by_keywords.impulse)


@pytest.mark.parametrize(("settings", "keywords"), [
    (LemkeSettings(tol=1e-10, polish=False, restarts=0, engine="tableau"),
     {"method": "lemke", "tol": 1e-10, "polish": False, "restarts": 0, "engine": "tableau"}),
    (PGSSettings(tol=1e-10, max_iter=5000, relaxation=1.1),
     {"method": "pgs", "tol": 1e-10, "max_iter": 5000, "relaxation": 1.1}),
])
def test_lcp_settings_give_the_keywords_answer(settings, keywords) -> None:
    by_object = coulomb.lcp.solve(M, Q3, settings=settings)
    by_keywords = coulomb.lcp.solve(M, Q3, **keywords)
    assert by_object.success
    np.testing.assert_array_equal(by_object.z, by_keywords.z)
    # the answer is an LCP solution: z >= 0, w >= 0, z . w = 0 on the original data
    w = M @ by_object.z + Q3
    assert by_object.z.min() >= 0 and w.min() >= -1e-10 and abs(by_object.z @ w) < 1e-10


def _ramp() -> coulomb.Scene:
    scene = coulomb.Scene(dim=2)
    block = scene.add(coulomb.Particle(mass=1.0, position=(0.0, 0.0), velocity=(1.0, 0.0)))
    floor = scene.add(coulomb.HalfSpace())
    scene.contact(scene.attach(block, coulomb.Point()), floor, mu=0.4)
    return scene


def test_step_settings_give_the_keywords_trajectory_and_the_sliding_block_stops() -> None:
    settings = StepSettings(solver=PolyhedralSettings(tol=1e-10), record_every=2)
    by_object = _ramp().simulate(0.5, 1e-3, settings=settings)
    by_keywords = _ramp().simulate(0.5, 1e-3, "lemke", tol=1e-10, record_every=2)
    np.testing.assert_array_equal(by_object.q, by_keywords.q)
    assert by_object.solver == "lemke" and by_object.record_every == 2
    # Coulomb friction on flat ground decelerates at mu g: stop at t = 1 / (0.4 * 9.81)
    stop = 1.0 / (0.4 * 9.81)
    moving = by_object.v[:, 0] > 1e-9
    assert abs(by_object.t[np.flatnonzero(~moving)[0]] - stop) <= 2 * 2e-3


def test_a_setting_given_twice_raises_a_settings_conflict() -> None:
    with pytest.raises(SettingsConflictError, match="tol"):
        coulomb.contact.solve(W3, Q3, 0.4, dim=3, tol=1e-6, settings=NSGSSettings())
    with pytest.raises(SettingsConflictError, match="method"):
        coulomb.contact.solve(W3, Q3, 0.4, 3, "lemke", settings=NSGSSettings())
    with pytest.raises(SettingsConflictError, match="max_pivots"):
        coulomb.lcp.solve(M, Q3, max_pivots=10, settings=LemkeSettings())
    with pytest.raises(SettingsConflictError, match="solver"):
        _ramp().simulate(0.1, 1e-3, "nsgs", settings=StepSettings())
    with pytest.raises(SettingsConflictError, match="drift"):
        _ramp().simulate(0.1, 1e-3, drift="bias", settings=StepSettings())
    assert issubclass(SettingsConflictError, InvalidParameterError)


def test_problem_data_combines_with_a_settings_object() -> None:
    first = coulomb.contact.solve(W3, Q3, 0.4, dim=3, settings=NSGSSettings(tol=1e-12))
    warm = coulomb.contact.solve(W3, Q3, 0.4, dim=3, initial=first.impulse,
                                 settings=NSGSSettings(tol=1e-12))
    assert warm.success and warm.iterations <= 2


@pytest.mark.parametrize(("make", "error"), [
    (lambda: NSGSSettings(tol=0.0), InvalidParameterError),
    (lambda: NSGSSettings(relaxation=2.0), InvalidParameterError),
    (lambda: NSGSSettings(order="random"), InvalidParameterError),
    (lambda: PolyhedralSettings(facets=7), InvalidParameterError),
    (lambda: LemkeSettings(max_pivots=1.5), ArgumentTypeError),
    (lambda: LemkeSettings(covering_vector=[1.0, float("nan")]), coulomb.errors.NonFiniteError),
    (lambda: PGSSettings(max_iter=0), InvalidParameterError),
    (lambda: ProxSettings(eta=0.0), InvalidParameterError),
    (lambda: StepSettings(solver="nsgs"), ArgumentTypeError),
    (lambda: StepSettings(solver=NSGSSettings(order="backward")), InvalidParameterError),
    (lambda: StepSettings(drift="spring"), InvalidParameterError),
    (lambda: StepSettings(warm_start=1), ArgumentTypeError),
])
def test_settings_fields_are_checked_when_made(make, error) -> None:
    with pytest.raises(error):
        make()


def test_settings_are_frozen_with_a_readable_repr() -> None:
    s = NSGSSettings(tol=1e-6)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.tol = 1e-3  # type: ignore[misc]
    assert repr(s) == ("NSGSSettings(tol=1e-06, max_iter=None, relaxation=1.0, order='forward', "
                       "sticking=True)")
    with pytest.raises(ArgumentTypeError):
        coulomb.lcp.solve(M, Q3, settings=NSGSSettings())
