"""``Scene.simulate(record_every=k)`` keeps every k-th state of the full run (and the last),
and a kept step's checks are the worst of the steps since the previous kept state: no solver
failure or violation is lost by recording less."""

from __future__ import annotations

import coulomb
import numpy as np
import pytest


def sliding_ball(mu: float = 0.2) -> coulomb.Scene:
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.Particle(mass=1.0, position=(0.0, 0.5), velocity=(0.5, 0.0)))
    s.contact(s.attach(b, coulomb.Point()), s.add(coulomb.HalfSpace()), mu=mu, e=0.5)
    return s


@pytest.mark.parametrize("k", [1, 3, 10, 1000, 5000])
def test_every_kth_state_of_the_full_run_is_kept(k):
    full = sliding_ball().simulate(2.0, 1e-3)
    part = sliding_ball().simulate(2.0, 1e-3, record_every=k)
    n = len(full.t) - 1
    kept = [s for s in range(1, n + 1) if s % k == 0 or s == n]
    assert part.record_every == k
    assert len(part.t) == len(kept) + 1
    np.testing.assert_array_equal(part.t[1:], full.t[kept])
    np.testing.assert_array_equal(part.q, full.q[[0, *kept]])
    np.testing.assert_array_equal(part.v, full.v[[0, *kept]])
    # the checks of a kept step: the worst over the steps it stands for
    starts = [0, *kept[:-1]]
    for row, (a, b) in enumerate(zip(starts, kept, strict=True)):
        assert part.momentum_residual[row] == full.momentum_residual[a:b].max()
        assert part.cone_violation[row] == full.cone_violation[a:b].max()
        assert part.min_normal_impulse[row] == full.min_normal_impulse[a:b].min()
        assert part.active[row] == full.active[a:b].max()
    # contact records of the kept steps only, indexed by row
    assert np.all(part.contact_step < len(kept))
    assert part.check().ok == full.check().ok


def landing_box() -> coulomb.Scene:
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.RigidBody2D(mass=1.0, inertia=0.1, position=(0.0, 0.5),
                                  velocity=(1.0, -0.5), angular_velocity=0.3))
    s.contact(s.attach(b, coulomb.Box((0.5, 0.5))), s.add(coulomb.HalfSpace()), mu=0.9)
    return s


def test_a_failed_step_is_never_lost():
    # two coupled corners, one NSGS sweep and no fallback: some solves miss the tolerance
    kw = {"max_iter": 1, "fallback": False, "tol": 1e-14}
    full = landing_box().simulate(1.0, 1e-3, **kw)
    failed = np.array([s not in ("solved", "no_contact") for s in full.solver_status])
    assert failed.any() and not failed.all()
    part = landing_box().simulate(1.0, 1e-3, record_every=50, **kw)
    windows = failed.reshape(-1, 50).any(axis=1)
    kept_failed = np.array([s not in ("solved", "no_contact") for s in part.solver_status])
    np.testing.assert_array_equal(kept_failed, windows)
    assert not part.success and not full.success
    np.testing.assert_array_equal(part.solver_error,
                                  full.solver_error.reshape(-1, 50).max(axis=1))
