"""Numerical stability at the extremes: scenes pushed to the ends of their parameters.

Each case runs a scene of :mod:`coulomb.model` at an extreme setting (mass ratios up to 1e6:
stacked disks, and a box on a box in generalized coordinates,
friction from 0 to 100, e = 0 and 1, steps from 1e-6 to 1e-1 s, grazing impacts, many
redundant contacts, the same scene in other units, Painleve's rod across theta and mu) and
compares one figure with its bound. A case *passes* when the figure is finite and within its
bound and every step's contact solve succeeded. When it does not, the case must say why: the
trajectory's own status (a step the solver could not finish) is then reported as a
:class:`ExtremeWarning` naming the cause. A case that is neither, a *false success*, fails the
suite.

``run()`` is the reduced form (seconds, run by the tests); ``run(full=True)`` the whole grid
(``python benches/extremes_report.py`` writes its report).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from .model import (
    GapContact,
    HalfSpace,
    Model,
    Particle,
    Point,
    Polygon,
    RigidBody2D,
    Scene,
    Segment,
    Sphere,
)
from .regularized import coulomb_ramp

__all__ = ["ExtremeCase", "ExtremeWarning", "format_report", "run"]

G0 = 9.81


class ExtremeWarning(UserWarning):
    """An extreme case missed its bound, and the trajectory said so (the message names why)."""


@dataclass(frozen=True)
class ExtremeCase:
    """One case of the suite."""

    family: str
    case: str
    quantity: str
    measured: float
    bound: float
    solved: bool
    message: str
    seconds: float

    @property
    def within(self) -> bool:
        return math.isfinite(self.measured) and abs(self.measured) <= self.bound

    @property
    def passed(self) -> bool:
        """within its bound, and every step solved."""
        return self.within and self.solved

    @property
    def honest(self) -> bool:
        """passed, or the trajectory reported its own failure (no false success)."""
        return self.passed or not self.solved


def _case(family: str, case: str, quantity: str, measured: float, bound: float, tr, t0: float):
    return ExtremeCase(
        family,
        case,
        quantity,
        float(measured),
        float(bound),
        bool(tr.success) and bool(np.all(np.isfinite(tr.q))),
        str(tr.message),
        time.perf_counter() - t0,
    )


def _floor(dim: int = 2) -> HalfSpace:
    return HalfSpace((0.0,) * dim, (0.0, 1.0) if dim == 2 else (0.0, 0.0, 1.0))


# ---- families ------------------------------------------------------------------------------


def _stillness_bound(ratio: float, h: float, t_end: float, tol: float = 1e-12) -> float:
    """How still a resting stack can stay: the contact solve is exact to ``tol`` relative to the
    largest impulse (the heavy body's ``m g h``), and that much impulse moves the light body by
    ``tol ratio g h`` per second. Floor: 1e-9 m."""
    return max(1e-9, tol * ratio * G0 * h * t_end)


def _mass_ratio(ratios: list[float]) -> Iterator[ExtremeCase]:
    """Two disks stacked on the floor, one `ratio` times heavier than the other, resting 1 s."""
    for ratio in ratios:
        for heavy_on_top in (True, False):
            t0 = time.perf_counter()
            m_top, m_bottom = (ratio, 1.0) if heavy_on_top else (1.0, ratio)
            scene = Scene(dim=2, gravity=(0.0, -G0))
            bottom = scene.add(Particle(mass=m_bottom, position=(0.0, 0.1)))
            top = scene.add(Particle(mass=m_top, position=(0.0, 0.3)))
            floor = scene.add(_floor())
            sb = scene.attach(bottom, Sphere(0.1))
            st = scene.attach(top, Sphere(0.1))
            scene.contact(sb, floor, mu=0.5)
            scene.contact(st, sb, mu=0.5)
            tr = scene.simulate(1.0, 1e-3)
            drift = float(np.max(np.abs(tr.q - tr.q[0])))
            order = "heavy on light" if heavy_on_top else "light on heavy"
            yield _case(
                "mass ratio",
                f"{ratio:g}, {order}",
                "drift (m)",
                drift,
                _stillness_bound(ratio, 1e-3, 1.0),
                tr,
                t0,
            )


def _point_contact(point: Callable[[np.ndarray], np.ndarray], height: float) -> GapContact:
    """The contact (mu = 0.5) of the point ``point(q)`` with the line ``y = height`` of the
    frame the point is given in: gap along y, tangential position along x."""
    return GapContact(
        gap=lambda q: float(point(q)[1] - height),
        tangent_position=lambda q: [float(point(q)[0])],
        mu=0.5,
    )


def _box_corner_gaps(a_bottom: float, a_top: float, b: float) -> list[GapContact]:
    """Gap contacts of a planar box (q[3:6]) resting on another (q[0:3]) resting on the floor,
    written in generalized coordinates: each bottom corner of the lower box against the floor,
    each bottom corner of the upper box against the lower box's top face (gap and tangential
    position measured in the lower box's frame, so their rates are the relative velocities)."""

    def corner(q: np.ndarray, k: int, sx: float, half: float) -> np.ndarray:
        x, y, th = q[3 * k : 3 * k + 3]
        c, s = math.cos(th), math.sin(th)
        return np.array([x + c * sx * half - s * (-b), y + s * sx * half + c * (-b)])

    contacts = []
    for sx in (-1.0, 1.0):

        def bottom(q: np.ndarray, sx: float = sx) -> np.ndarray:
            return corner(q, 0, sx, a_bottom)

        contacts.append(_point_contact(bottom, 0.0))

        def local(q: np.ndarray, sx: float = sx) -> np.ndarray:
            p = corner(q, 1, sx, a_top)
            x, y, th = q[0:3]
            c, s = math.cos(th), math.sin(th)
            d = p - np.array([x, y])
            return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

        contacts.append(_point_contact(local, b))
    return contacts


def _constant_force(g: np.ndarray) -> Callable[[np.ndarray, np.ndarray, float], np.ndarray]:
    """The generalized force ``f(q, v, t) = g``."""
    return lambda q, v, t: g


def _linear_potential(g: np.ndarray) -> Callable[[np.ndarray], float]:
    """The potential ``-g . q`` of the constant generalized force g."""
    return lambda q: float(-(g @ q))


def _mass_ratio_boxes(ratios: list[float]) -> Iterator[ExtremeCase]:
    """A box resting on another box on the floor, one `ratio` times heavier than the other
    (generalized coordinates, both boxes planar rigid bodies), 0.5 s: no drift."""
    b = 0.05
    for ratio in ratios:
        for heavy_on_top in (True, False):
            t0 = time.perf_counter()
            m_top, m_bottom = (ratio, 1.0) if heavy_on_top else (1.0, ratio)
            a_bottom, a_top = 0.2, 0.1
            j_bottom = m_bottom * (4 * a_bottom**2 + 4 * b * b) / 12
            j_top = m_top * (4 * a_top**2 + 4 * b * b) / 12
            mass = np.diag([m_bottom, m_bottom, j_bottom, m_top, m_top, j_top])
            gravity = np.array([0.0, -G0 * m_bottom, 0.0, 0.0, -G0 * m_top, 0.0])
            model = Model(
                2,
                mass,
                q0=[0.0, b, 0.0, 0.03, 3 * b, 0.0],
                force=_constant_force(gravity),
                contacts=_box_corner_gaps(a_bottom, a_top, b),
                potential=_linear_potential(gravity),
            )
            tr = model.simulate(0.5, 1e-3)
            drift = float(np.max(np.abs(tr.q - tr.q[0])))
            order = "heavy on light" if heavy_on_top else "light on heavy"
            yield _case(
                "mass ratio",
                f"boxes {ratio:g}, {order}",
                "drift (m)",
                drift,
                _stillness_bound(ratio, 1e-3, 0.5),
                tr,
                t0,
            )


def _friction(mus: list[float]) -> Iterator[ExtremeCase]:
    """The chapter's ramp (20 deg, v0 = 1 m/s, h = 1 ms) from frictionless to mu = 100: the
    distance at t = 2 s against the exact Coulomb answer."""
    th = math.radians(20.0)
    h = 1e-3
    for mu in mus:
        t0 = time.perf_counter()
        scene = Scene(dim=2, gravity=(0.0, -G0))
        block = scene.add(
            Particle(mass=1.0, position=(0.0, 0.0), velocity=(math.cos(th), -math.sin(th)))
        )
        scene.contact(scene.attach(block, Point()), scene.add(HalfSpace.ramp(20.0)), mu=mu)
        tr = scene.simulate(2.0, h)
        s = tr.q[-1, 0] * math.cos(th) - tr.q[-1, 1] * math.sin(th)
        exact, _ = coulomb_ramp(th, mu, 1.0, np.array([tr.t[-1]]))
        # the stepper's position error is first order: h times the speed scale
        bound = 2.0 * h * (1.0 + G0 * tr.t[-1])
        yield _case("friction", f"mu = {mu:g}", "distance error (m)", s - exact[0], bound, tr, t0)


def _restitution(bounces: int) -> Iterator[ExtremeCase]:
    """e = 1 for `bounces` bounces: no energy gain; e = 0: no rebound at all."""
    t0 = time.perf_counter()
    drop = 0.01
    period = 2.0 * math.sqrt(2.0 * drop / G0)
    scene = Scene(dim=2, gravity=(0.0, -G0))
    ball = scene.add(Particle(mass=1.0, position=(0.0, drop)))
    scene.contact(scene.attach(ball, Point()), scene.add(_floor()), e=1.0)
    tr = scene.simulate(bounces * period, 1e-4)
    # energy at the apexes: within a step that holds an impact the discrete state passes
    # through O(m g |v| h) excursions, but no bounce may end with more energy than the first
    y = tr.q[:, 1]
    apex = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    if len(apex) < bounces - 1:
        gain = math.inf  # fewer bounces than expected: the ball lost its motion
    else:
        e_apex = tr.total_energy[apex]
        gain = max(float(np.max(e_apex - e_apex[0])), 0.0)
    yield _case(
        "restitution", f"e = 1, {bounces} bounces", "apex energy gain (J)", gain, 1e-12, tr, t0
    )
    t0 = time.perf_counter()
    scene = Scene(dim=2, gravity=(0.0, -G0))
    ball = scene.add(Particle(mass=1.0, position=(0.0, drop)))
    scene.contact(scene.attach(ball, Point()), scene.add(_floor()), e=0.0)
    tr = scene.simulate(5 * period, 1e-4)
    k = int(np.argmin(tr.q[:, 1] > 1e-12)) or len(tr.t) - 1
    rebound = float(np.max(tr.q[k:, 1]))
    yield _case("restitution", "e = 0", "height after impact (m)", rebound, 1e-12, tr, t0)


def _step_size(hs: list[float]) -> Iterator[ExtremeCase]:
    """The floor impact (0.5 kg, -3 m/s, e = 0.6) at step sizes from 1e-6 to 1e-1 s."""
    for h in hs:
        t0 = time.perf_counter()
        scene = Scene(dim=2, gravity=(0.0, 0.0))
        ball = scene.add(Particle(mass=0.5, position=(0.0, 0.4 * 3.0 * h), velocity=(0.0, -3.0)))
        scene.contact(scene.attach(ball, Point()), scene.add(_floor()), e=0.6)
        tr = scene.simulate(4 * h, h)
        yield _case(
            "step size", f"h = {h:g} s", "rebound error (m/s)", tr.v[-1, 1] - 1.8, 1e-9, tr, t0
        )


def _grazing(speeds: list[float]) -> Iterator[ExtremeCase]:
    """A sliding particle meets the floor at a tiny normal speed: it must rebound at exactly
    e |v_n| (e = 0.5) and never lift off more."""
    for vn in speeds:
        t0 = time.perf_counter()
        h = 1e-3
        scene = Scene(dim=2, gravity=(0.0, 0.0))
        ball = scene.add(Particle(mass=1.0, position=(0.0, 0.5 * vn * h), velocity=(1.0, -vn)))
        scene.contact(scene.attach(ball, Point()), scene.add(_floor()), mu=0.3, e=0.5)
        tr = scene.simulate(5 * h, h)
        err = (tr.v[-1, 1] - 0.5 * vn) / vn
        yield _case(
            "grazing impact", f"v_n = {vn:g} m/s", "relative rebound error", err, 1e-6, tr, t0
        )


def _redundant(counts: list[int]) -> Iterator[ExtremeCase]:
    """A planar block resting on `count` collinear contact points (W singular), 2 s, both
    solvers: no drift, no jitter."""
    for count in counts:
        for solver in ("nsgs", "lemke"):
            t0 = time.perf_counter()
            scene = Scene(dim=2, gravity=(0.0, -G0))
            xs = np.linspace(-0.2, 0.2, count)
            body = scene.add(RigidBody2D(mass=2.0, inertia=0.05, position=(0.0, 0.05)))
            scene.contact(
                scene.attach(body, Polygon([(x, -0.05) for x in xs])), scene.add(_floor()), mu=0.5
            )
            tr = scene.simulate(2.0, 1e-3, solver)
            drift = float(np.max(np.abs(tr.q - tr.q[0])))
            yield _case(
                "redundant contacts", f"{count} points, {solver}", "drift (m)", drift, 1e-9, tr, t0
            )


def _units(factors: list[float]) -> Iterator[ExtremeCase]:
    """The chapter's ramp with lengths in other units (positions, speeds and g scaled by the
    factor): the stop distance scales by the same factor."""
    th = math.radians(20.0)

    def stop(factor: float):
        scene = Scene(dim=2, gravity=(0.0, -G0 * factor))
        block = scene.add(
            Particle(
                mass=1.0,
                position=(0.0, 0.0),
                velocity=(factor * math.cos(th), -factor * math.sin(th)),
            )
        )
        scene.contact(scene.attach(block, Point()), scene.add(HalfSpace.ramp(20.0)), mu=0.4)
        tr = scene.simulate(5.0, 1e-3, gap_tolerance=1e-9 * factor)
        return tr, tr.q[-1, 0] * math.cos(th) - tr.q[-1, 1] * math.sin(th)

    _, base = stop(1.0)
    for f in factors:
        t0 = time.perf_counter()
        tr, s = stop(f)
        yield _case(
            "units",
            f"lengths x {f:g}",
            "relative change of the scaled answer",
            s / f / base - 1.0,
            1e-9,
            tr,
            t0,
        )


def _painleve(grid: list[tuple[float, float]]) -> Iterator[ExtremeCase]:
    """Painleve's rod, its end sliding left at 1 m/s, across theta and mu: every step solved
    and the energy never increases."""
    for theta_deg, mu in grid:
        t0 = time.perf_counter()
        th = math.radians(theta_deg)
        scene = Scene(dim=2, gravity=(0.0, -G0))
        rod = scene.add(
            RigidBody2D(
                mass=1.0,
                inertia=1.0 / 12.0,
                position=(0.0, 0.5 * math.sin(th)),
                angle=th,
                velocity=(-1.0, 0.0),
            )
        )
        scene.contact(
            scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), scene.add(_floor()), mu=mu
        )
        tr = scene.simulate(0.5, 1e-3)
        gain = float(np.max(np.diff(tr.total_energy)))
        yield _case(
            "Painleve rod",
            f"theta = {theta_deg:g} deg, mu = {mu:g}",
            "largest energy gain per step (J)",
            max(gain, 0.0),
            1e-9,
            tr,
            t0,
        )


def run(
    full: bool = False, progress: Callable[[ExtremeCase], None] | None = None
) -> list[ExtremeCase]:
    """Runs the suite (reduced unless ``full``); warns :class:`ExtremeWarning` for every case
    that missed its bound with the trajectory's own reason."""
    if full:
        families = [
            _mass_ratio([1.0, 1e2, 1e4, 1e6]),
            _mass_ratio_boxes([1.0, 1e3, 1e6]),
            _friction([0.0, 1e-6, 0.1, 0.3, 0.4, 1.0, 10.0, 100.0]),
            _restitution(1000),
            _step_size([1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1]),
            _grazing([1e-3, 1e-6, 1e-9]),
            _redundant([2, 8, 32, 128]),
            _units([1e-3, 1e3]),
            _painleve(
                [(t, m) for t in (20.0, 30.0, 45.0, 60.0, 75.0) for m in (0.3, 1.0, 2.0, 5.0)]
            ),
        ]
    else:
        families = [
            _mass_ratio([1e6]),
            _mass_ratio_boxes([1e6]),
            _friction([0.0, 1e-6, 100.0]),
            _restitution(100),
            _step_size([1e-6, 1e-1]),
            _grazing([1e-9]),
            _redundant([32]),
            _units([1e-3, 1e3]),
            _painleve([(45.0, 2.0), (30.0, 5.0)]),
        ]
    out: list[ExtremeCase] = []
    for fam in families:
        for c in fam:
            if not c.passed and c.honest:
                warnings.warn(
                    f"{c.family}, {c.case}: {c.quantity} {c.measured:.3g} (bound {c.bound:g}); "
                    f"the trajectory reports: {c.message}",
                    ExtremeWarning,
                    stacklevel=2,
                )
            out.append(c)
            if progress is not None:
                progress(c)
    return out


def format_report(cases: list[ExtremeCase]) -> str:
    """A markdown table of the cases."""
    lines = [
        "| family | case | quantity | measured | bound | steps solved | verdict | time (s) |",
        "|---|---|---|---:|---:|---|---|---:|",
    ]
    for c in cases:
        verdict = "pass" if c.passed else ("warned" if c.honest else "**FALSE SUCCESS**")
        lines.append(
            f"| {c.family} | {c.case} | {c.quantity} | {c.measured:.3g} | {c.bound:g} | "
            f"{'yes' if c.solved else 'no: ' + c.message} | {verdict} | {c.seconds:.2f} |"
        )
    return "\n".join(lines)
