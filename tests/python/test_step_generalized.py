"""User-defined models in generalized coordinates (stepped by the Rust stepper through
callbacks) agree with the built-in bodies on the seed's scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from coulomb import GapContact, HalfSpace, Model, Particle, Point, Scene
from coulomb.errors import InvalidParameterError
from hypothesis import given, settings
from hypothesis import strategies as st

G = 9.81
TH = math.radians(45.0)


def rod_model(analytic: bool) -> Model:
    # q = (x, y, theta): the seed's rod, lower end at (x - cos(theta) / 2, y - sin(theta) / 2)
    def gap(q):
        return q[1] - 0.5 * math.sin(q[2])

    def jn(q):
        return [0.0, 1.0, -0.5 * math.cos(q[2])]

    def jt(q):
        return [[1.0, 0.0, 0.5 * math.sin(q[2])]]

    def s(q):
        return [q[0] - 0.5 * math.cos(q[2])]

    contact = (GapContact(gap, jn, jt, mu=2.0) if analytic
               else GapContact(gap, tangent_position=s, mu=2.0))
    return Model(dim=2, mass_matrix=np.diag([1.0, 1.0, 1 / 12]),
                 q0=[0.0, 0.5 * math.sin(TH), TH], v0=[-1.0, 0.0, 0.0],
                 force=lambda q, v, t: [0.0, -G, 0.0], contacts=[contact],
                 potential=lambda q: G * q[1])


def rod_scene() -> Scene:
    from coulomb import RigidBody2D, Segment

    scene = Scene(dim=2)
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, position=(0.0, 0.5 * math.sin(TH)),
                                angle=TH, velocity=(-1.0, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    return scene


@pytest.mark.parametrize("analytic", [True, False])
def test_painleve_rod_as_a_generalized_model_matches_the_built_in_body(analytic):
    a = rod_model(analytic).simulate(0.1, 1e-3)
    b = rod_scene().simulate(0.1, 1e-3)
    tol = 1e-10 if analytic else 1e-6
    assert np.max(np.abs(a.q - b.q)) < tol
    assert np.max(np.abs(a.v - b.v)) < 10 * tol
    first = a.contact_step == 0
    assert abs(a.contact_velocity[first][0, 1]) < 1e-8  # jams in one step
    assert a.check().ok, a.check().violations
    np.testing.assert_allclose(a.total_energy, b.total_energy, atol=10 * tol)


def test_floor_impact_generalized():
    model = Model(dim=2, mass_matrix=[[0.5, 0.0], [0.0, 0.5]], q0=[0.0, 0.001],
                  v0=[0.0, -3.0],
                  contacts=[GapContact(lambda q: q[1], lambda q: [0.0, 1.0],
                                       lambda q: [[1.0, 0.0]], e=0.6)])
    tr = model.simulate(0.004, 1e-3)
    assert tr.v[-1, 1] == pytest.approx(1.8, abs=1e-12)
    assert tr.contact_impulse[:, 0].sum() == pytest.approx(2.4, abs=1e-12)
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    p = scene.add(Particle(mass=0.5, position=(0.0, 0.001), velocity=(0.0, -3.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(p, Point()), floor, e=0.6)
    np.testing.assert_allclose(tr.q, scene.simulate(0.004, 1e-3).q, atol=1e-15)


def test_generalized_input_checks():
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=[[1.0, 0.0], [0.0, -1.0]], q0=[0.0, 0.0])
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.0],
              contacts=[GapContact(lambda q: q[1], mu=0.5)])
    with pytest.raises(InvalidParameterError):
        Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.0],
              contacts=[GapContact(lambda q: q[1], e=2.0)])


# --- the Rust stepper drives models through callbacks: a model of the same bodies gives the
# scene's figures to rounding, with every option scenes have


def ramp_particle_model(mu: float, v0: tuple[float, float], th: float = 0.3) -> Model:
    s, c = math.sin(th), math.cos(th)
    return Model(dim=2, mass_matrix=2.0 * np.eye(2), q0=[0.0, 0.0], v0=list(v0),
                 force=lambda q, v, t: [0.0, -2.0 * G],
                 contacts=[GapContact(lambda q: -s * q[0] + c * q[1], lambda q: [-s, c],
                                      lambda q: [[c, s]], mu=mu)],
                 potential=lambda q: 2.0 * G * q[1])


def ramp_particle_scene(mu: float, v0: tuple[float, float], th: float = 0.3) -> Scene:
    scene = Scene(dim=2, gravity=(0.0, -G))
    p = scene.add(Particle(mass=2.0, position=(0.0, 0.0), velocity=v0))
    ramp = scene.add(HalfSpace((0.0, 0.0), (-math.sin(th), math.cos(th))))
    scene.contact(scene.attach(p, Point()), ramp, mu=mu)
    return scene


def assert_same_run(a, b, tol: float) -> None:
    scale = max(1.0, float(np.abs(b.q).max()), float(np.abs(b.v).max()))
    assert np.abs(a.q - b.q).max() <= tol * scale
    assert np.abs(a.v - b.v).max() <= tol * scale
    np.testing.assert_array_equal(a.active, b.active)
    np.testing.assert_allclose(a.total_energy, b.total_energy, rtol=0, atol=tol * scale ** 2)
    # the per-step verdict and the checks are the scenes'
    assert list(a.solver_status) == list(b.solver_status)
    assert np.all(a.solver_scaled_error <= max(a.tol, 1e-9))


@pytest.mark.parametrize(("mu", "v0"), [(0.1, (0.0, 0.0)),
                                        (0.5, (-0.5 * math.cos(0.3), -0.5 * math.sin(0.3)))])
def test_a_particle_on_a_ramp_as_a_model_gives_the_scenes_figures(mu, v0):
    a = ramp_particle_model(mu, v0).simulate(0.5, 1e-3)
    b = ramp_particle_scene(mu, v0).simulate(0.5, 1e-3)
    assert_same_run(a, b, 1e-12)
    assert a.check().ok, a.check().violations
    # sliding down, the velocity along the ramp (c, s) changes at g (mu cos th - sin th) (mu
    # = 0.1 speeds up; mu = 0.5 > tan th stops within the 0.5 s and sticks)
    s, c = math.sin(0.3), math.cos(0.3)
    expected = min(0.0, (v0[0] * c + v0[1] * s) + 0.5 * G * (mu * c - s))
    assert a.v[-1] @ [c, s] == pytest.approx(expected, abs=1e-9)


def rod_end_model(e: float, mu: float, q0: list[float], v0: list[float]) -> Model:
    def gap(q):
        return q[1] - 0.5 * math.sin(q[2])

    return Model(dim=2, mass_matrix=np.diag([1.0, 1.0, 1 / 12]), q0=q0, v0=v0,
                 contacts=[GapContact(gap, lambda q: [0.0, 1.0, -0.5 * math.cos(q[2])],
                                      lambda q: [[1.0, 0.0, 0.5 * math.sin(q[2])]],
                                      mu=mu, e=e)])


def rod_end_scene(e: float, mu: float, q0: list[float], v0: list[float]) -> Scene:
    from coulomb import RigidBody2D

    scene = Scene(dim=2, gravity=(0.0, 0.0))
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, angle=q0[2],
                                position=(q0[0], q0[1]), velocity=(v0[0], v0[1]),
                                angular_velocity=v0[2]))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Point(offset=(-0.5, 0.0))), floor, mu=mu, e=e)
    return scene


@pytest.mark.parametrize(("e", "mu"), [(0.6, 0.0), (1.0, 0.0), (0.6, 0.4)])
def test_a_rod_end_striking_mid_step_rebounds_by_newtons_law_as_the_scene(e, mu):
    h, th = 1e-3, math.radians(30)
    q0, v0 = [0.0, 0.5 * math.sin(th) + 2.5 * h, th], [0.0, -1.0, 0.0]
    a = rod_end_model(e, mu, q0, v0).simulate(6 * h, h)
    b = rod_end_scene(e, mu, q0, v0).simulate(6 * h, h)
    assert_same_run(a, b, 1e-12)
    assert a.resumed.any()  # the rebound came from the impact memory
    ang, (vy, w) = a.q[-1, 2], a.v[-1, 1:]
    if mu == 0.0:
        assert vy - w * 0.5 * math.cos(ang) == pytest.approx(e, rel=1e-2)
    assert a.check().ok, a.check().violations


def test_poissons_law_on_a_model_keeps_friction_in_both_phases():
    # v = (1, -3), mu = 0.2, e = 0.5: friction in compression and restitution leaves
    # v_t = 1 - 0.2 (3 + 1.5) = 0.1 and v_n = 1.5
    model = Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.0], v0=[1.0, -3.0],
                  contacts=[GapContact(lambda q: q[1], lambda q: [0.0, 1.0],
                                       lambda q: [[1.0, 0.0]], mu=0.2, e=0.5)])
    tr = model.simulate(2e-3, 1e-3, restitution="poisson")
    assert tr.v[1] == pytest.approx([0.1, 1.5], abs=1e-12)
    # Newton's law pushes P_n = 4.5 at once: sliding friction 0.9 leaves the same v_t here
    newton = model.simulate(2e-3, 1e-3)
    assert newton.v[1] == pytest.approx([0.1, 1.5], abs=1e-12)
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    p = scene.add(Particle(mass=1.0, position=(0.0, 0.0), velocity=(1.0, -3.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(p, Point()), floor, mu=0.2, e=0.5)
    assert_same_run(tr, scene.simulate(2e-3, 1e-3, restitution="poisson"), 1e-14)


@pytest.mark.parametrize("drift", ["none", "bias", "projection"])
def test_the_drift_options_on_a_model_as_on_the_scene(drift):
    # the rod lands on its end and slides down under gravity
    from coulomb import RigidBody2D

    q0, v0 = [0.0, 0.5 * math.sin(0.6) + 0.01, 0.6], [0.3, -0.5, 1.0]
    model = rod_end_model(0.5, 0.3, q0, v0)
    model.force = lambda q, v, t: [0.0, -G, 0.0]
    model.potential = lambda q: G * q[1]
    scene = Scene(dim=2, gravity=(0.0, -G))
    rod = scene.add(RigidBody2D(mass=1.0, inertia=1 / 12, angle=q0[2], position=(q0[0], q0[1]),
                                velocity=(v0[0], v0[1]), angular_velocity=v0[2]))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Point(offset=(-0.5, 0.0))), floor, mu=0.3, e=0.5)
    a = model.simulate(0.4, 1e-3, drift=drift)
    b = scene.simulate(0.4, 1e-3, drift=drift)
    assert_same_run(a, b, 1e-9)
    assert np.abs(a.projection - b.projection).max() <= 1e-9
    assert (a.projection.max() > 0) == (drift == "projection")
    if drift == "projection":
        assert a.min_gap.min() >= -1e-9


def test_record_every_on_a_model_folds_the_unrecorded_steps():
    full = ramp_particle_model(0.1, (0.0, 0.0)).simulate(0.1, 1e-3)
    every = ramp_particle_model(0.1, (0.0, 0.0)).simulate(0.1, 1e-3, record_every=10)
    assert len(every.t) == 11
    np.testing.assert_array_equal(every.q, full.q[::10])
    assert every.solver_error.max() == full.solver_error.max()
    assert every.momentum_residual.max() == full.momentum_residual.max()


class CallbackFailure(Exception):
    pass


def _raise_after(t0: float, value):
    def f(*args):
        t = args[2] if len(args) == 3 else None
        if t is not None and t > t0:
            raise CallbackFailure(f"failed at t = {t}")
        return value
    return f


def test_an_exception_raised_in_a_callback_surfaces_as_itself():
    model = ramp_particle_model(0.1, (0.0, 0.0))
    model.force = _raise_after(0.005, [0.0, -2.0 * G])
    with pytest.raises(CallbackFailure, match=r"failed at t = 0\.006"):
        model.simulate(0.1, 1e-3)
    calls = []

    def gap(q):
        calls.append(1)
        if len(calls) > 3:
            raise KeyError("gap gave up")
        return q[1]

    bad = Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 1.0],
                contacts=[GapContact(gap, lambda q: [0.0, 1.0])])
    with pytest.raises(KeyError, match="gap gave up"):
        bad.simulate(0.1, 1e-3)
    heavy = Model(dim=1 + 1, mass_matrix=lambda q: np.eye(2) if q[1] > 0.99 else -np.eye(2),
                  q0=[0.0, 1.0], v0=[0.0, -1.0])
    with pytest.raises(InvalidParameterError, match="positive definite"):
        heavy.simulate(0.1, 1e-3)


def tilted_normal() -> np.ndarray:
    n = np.array([0.2, -0.3, 1.0])
    return n / np.linalg.norm(n)


@pytest.mark.parametrize("solver", ["nsgs", "lemke"])
@pytest.mark.parametrize("mu", [0.0, 0.2, 1.0])
def test_a_spatial_particle_on_a_tilted_plane_as_a_model_gives_the_scenes_figures(solver, mu):
    # dim 3: two tangent rows (any orthonormal pair: the disk and the polygon's facets are
    # rotated with it, so Lemke's 3D answer is compared with friction only when isotropic)
    n = tilted_normal()
    t1 = np.cross(n, [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    q0, v0 = [0.0, 0.0, 0.002], [0.5, 0.2, -1.0]
    model = Model(dim=3, mass_matrix=0.5 * np.eye(3), q0=q0, v0=v0,
                  force=lambda q, v, t: [0.0, 0.0, -0.5 * G],
                  contacts=[GapContact(lambda q: float(n @ q), lambda q: n,
                                       lambda q: np.array([t1, t2]), mu=mu, e=0.3)],
                  potential=lambda q: 0.5 * G * q[2])
    scene = Scene(dim=3, gravity=(0.0, 0.0, -G))
    p = scene.add(Particle(mass=0.5, position=q0, velocity=v0))
    plane = scene.add(HalfSpace((0.0, 0.0, 0.0), tuple(n)))
    scene.contact(scene.attach(p, Point()), plane, mu=mu, e=0.3)
    a = model.simulate(0.3, 1e-3, solver=solver)
    b = scene.simulate(0.3, 1e-3, solver=solver)
    assert a.active.any()
    if solver == "nsgs" or mu == 0.0:
        assert_same_run(a, b, 1e-9)
    else:
        # Lemke's polygon depends on the tangent frame: the same law to its facet error
        assert np.abs(a.q - b.q).max() < 1e-2 and a.check().ok
    # the particle stays on the plane (n . q >= -gap tolerance up to the step's drift)
    assert float((a.q @ n).min()) > -1e-6


@settings(max_examples=25, deadline=None, derandomize=True)
@given(dim=st.sampled_from([2, 3]), mass=st.floats(1e-3, 1e3),
       mu=st.sampled_from([0.0, 0.3, 1.0, 1e3]), e=st.floats(0.0, 1.0),
       tilt=st.floats(-0.6, 0.6), speed=st.floats(0.1, 10.0),
       law=st.sampled_from(["newton", "poisson"]))
def test_particle_models_give_the_scenes_figures_over_the_class(dim, mass, mu, e, tilt, speed,
                                                                law):
    # a particle thrown at a tilted plane under gravity, as a model and as a scene
    n = np.zeros(dim)
    n[0], n[-1] = math.sin(tilt), math.cos(tilt)
    basis = np.linalg.svd(n.reshape(1, -1))[2][1:]  # an orthonormal tangent basis
    q0 = list(0.01 * n)
    v0 = list(-speed * n + 0.3 * speed * basis[0])
    g = np.zeros(dim)
    g[-1] = -G
    model = Model(dim=dim, mass_matrix=mass * np.eye(dim), q0=q0, v0=v0,
                  force=lambda q, v, t: mass * g,
                  contacts=[GapContact(lambda q: float(n @ q), lambda q: n, lambda q: basis,
                                       mu=mu, e=e)],
                  potential=lambda q: -mass * float(g @ q))
    scene = Scene(dim=dim, gravity=tuple(g))
    p = scene.add(Particle(mass=mass, position=q0, velocity=v0))
    plane = scene.add(HalfSpace(tuple([0.0] * dim), tuple(n)))
    scene.contact(scene.attach(p, Point()), plane, mu=mu, e=e)
    a = model.simulate(0.05, 1e-3, restitution=law)
    b = scene.simulate(0.05, 1e-3, restitution=law)
    assert a.active.any()
    assert_same_run(a, b, 1e-9)
    assert a.check().ok == b.check().ok


def test_a_model_run_holds_the_gil_only_while_calling_back():
    import sys
    import threading

    # each force callback starts a thread with about 1 ms of Python work and returns; Rust
    # then factors a 400 x 400 M(q) (milliseconds) before the next callback, which looks
    # whether the thread has finished. Had Rust kept the GIL, the thread could run only at the
    # next callback's first bytecodes (a switch interval, 0.1 ms), never long enough to finish
    n = 400
    rng = np.random.default_rng(3)
    a = rng.standard_normal((n, n))
    mass = np.ascontiguousarray(a @ a.T / n + np.eye(n))
    done: list[bool] = []
    running: list[threading.Event] = []

    def work(event: threading.Event) -> None:
        total = 0
        for k in range(20_000):
            total += k
        event.set()

    def force(q, v, t):
        if running:
            done.append(running[-1].is_set())
            running[-1].wait()
        event = threading.Event()
        running.append(event)
        threading.Thread(target=work, args=(event,)).start()
        return np.zeros(n)

    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        model = Model(dim=2, mass_matrix=mass, q0=np.zeros(n), force=force)
        model.simulate(0.02, 1e-3)
    finally:
        sys.setswitchinterval(old)
        for event in running:
            event.wait()
    assert len(done) == 20
    assert sum(done) >= 1, done


# --- located impacts: a model's isolated impact is found within its step as a scene's


def bouncing_particle_model(e: float) -> Model:
    return Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 1.0], v0=[0.1, 0.0],
                 force=lambda q, v, t: [0.0, -G],
                 contacts=[GapContact(lambda q: q[1], lambda q: [0.0, 1.0],
                                      lambda q: [[1.0, 0.0]], e=e)],
                 potential=lambda q: G * q[1])


def bouncing_particle_scene(e: float) -> Scene:
    scene = Scene(dim=2, gravity=(0.0, -G))
    p = scene.add(Particle(mass=1.0, position=(0.0, 1.0), velocity=(0.1, 0.0)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(p, Point()), floor, e=e)
    return scene


def test_a_located_elastic_bounce_on_a_model_keeps_the_apex_energy_as_the_scene():
    # 20 bounces at h = 1e-3 (the Rust test runs 100): the flight energy T + V + (h/2) f.v is
    # kept to 1e-9, where the plain step loses m g y_k per bounce
    h = 1e-3
    t_end = 20 * 2.0 * math.sqrt(2.0 / G) + 0.05
    a = bouncing_particle_model(1.0).simulate(t_end, h, locate_impacts=True)
    b = bouncing_particle_scene(1.0).simulate(t_end, h, locate_impacts=True)
    assert_same_run(a, b, 1e-9)
    flight = a.total_energy + 0.5 * h * a.load_power
    assert abs(flight[-1] - flight[0]) <= 1e-9 * flight[0]
    assert int(np.sum(a.contact_impulse[:, 0] > 0)) >= 20
    plain = bouncing_particle_model(1.0).simulate(t_end, h)
    lost = (plain.total_energy + 0.5 * h * plain.load_power)
    assert flight[0] - lost[-1] > 1e-4 * flight[0]
    assert a.check().ok, a.check().violations


@pytest.mark.parametrize(("e", "mu"), [(1.0, 0.0), (0.6, 0.4)])
def test_a_located_rod_end_impact_on_a_model_as_the_scene(e, mu):
    h, th = 1e-3, math.radians(30)
    q0, v0 = [0.0, 0.5 * math.sin(th) + 2.5 * h, th], [0.0, -1.0, 0.0]
    a = rod_end_model(e, mu, q0, v0).simulate(6 * h, h, locate_impacts=True)
    b = rod_end_scene(e, mu, q0, v0).simulate(6 * h, h, locate_impacts=True)
    assert_same_run(a, b, 1e-9)
    assert not a.resumed.any()  # the rebound is given at the instant, not owed
    if mu == 0.0:
        assert a.kinetic_energy[-1] == pytest.approx(a.kinetic_energy[0], rel=1e-12)
