"""Trajectory is a class with documented attributes, not a dict: what help() and dir() show,
the statuses as coulomb.Status, and values that follow from the physics of a falling ball."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest
from coulomb import Status


def _ball(t_end: float = 0.5, h: float = 1e-3) -> coulomb.Trajectory:
    scene = coulomb.Scene(dim=2)
    ball = scene.add(coulomb.Particle(mass=0.5, position=(0.0, 0.2)))
    floor = scene.add(coulomb.HalfSpace())
    scene.contact(scene.attach(ball, coulomb.Point()), floor, mu=0.3)
    return scene.simulate(t_end, h)


def test_trajectory_attributes_are_documented_and_dict_methods_are_gone() -> None:
    names = set(dir(coulomb.Trajectory))
    for attr in ("t", "q", "v", "solver_status", "contact_impulse", "success", "status",
                 "message", "total_energy", "scene", "record_every"):
        assert attr in names
        assert f"{attr} :" in coulomb.Trajectory.__doc__ or f", {attr}" in \
            coulomb.Trajectory.__doc__ or f"{attr}, " in coulomb.Trajectory.__doc__
    assert not {"pop", "popitem", "keys", "items", "update"} & names
    assert not issubclass(coulomb.Trajectory, dict)


def test_trajectory_statuses_are_status_members_and_values_follow_free_fall() -> None:
    tr = _ball()
    assert tr.status is Status.COMPLETED and tr.success
    assert all(isinstance(s, Status) for s in tr.solver_status)
    # free fall from 0.2 m lands at t = sqrt(2 * 0.2 / 9.81) = 0.2019 s: no contact before
    landing = np.sqrt(2 * 0.2 / 9.81)
    before = tr.t[:-1] < landing - 2e-3
    assert all(s is Status.NO_CONTACT for s in tr.solver_status[before])
    assert Status.SOLVED in set(tr.solver_status[~before])
    np.testing.assert_allclose(tr.total_energy, tr.kinetic_energy + tr.potential_energy)
    assert tr.q.shape == (len(tr.t), 2) and tr.h == 1e-3 and tr.dim == 2
    assert tr.scene is not None and tr.record_every == 1


def test_trajectory_repr_summarises_the_run() -> None:
    tr = _ball()
    text = repr(tr)
    assert text.startswith("Trajectory(500 steps of h = 0.001 s")
    assert "solved:" in text and "no_contact:" in text


def test_trajectory_is_made_by_simulate_only() -> None:
    with pytest.raises(TypeError):
        coulomb.Trajectory()


def test_trajectory_pickles_for_executors() -> None:
    import pickle

    tr = _ball(0.3)
    back = pickle.loads(pickle.dumps(tr))
    np.testing.assert_array_equal(back.q, tr.q)
    assert back.status is Status.COMPLETED and back.scene is not None
    assert list(back.solver_status) == list(tr.solver_status)
