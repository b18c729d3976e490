r"""Scenes: bodies, contact shapes, half-spaces and contact pairs, simulated by Stewart's
(2000) impulse time stepper (the whole loop runs in Rust, with the GIL released).

A planar scene (``dim=2``) has particles ``(x, y)`` and planar rigid bodies ``(x, y, theta)``;
a spatial scene (``dim=3``) has particles ``(x, y, z)`` and spatial rigid bodies (position, unit
quaternion ``(w, x, y, z)``; velocities: linear, then the angular velocity in the world frame;
inertia in the body frame). Contact shapes are sets of body-frame points with a radius
(:class:`Point`, :class:`Sphere`/:class:`Disk`, :class:`Segment` ends, :class:`Box` and
:class:`Polygon` corners); a pair is a shape against a static :class:`HalfSpace` (floor, ramp,
wall) or a sphere against a sphere, each with its friction coefficient ``mu`` and Newton
restitution coefficient ``e``.

>>> import coulomb
>>> scene = coulomb.Scene(dim=2, gravity=(0.0, -9.81))
>>> ball = scene.add(coulomb.Particle(mass=0.5, position=(0.0, 0.0), velocity=(0.0, -3.0)))
>>> floor = scene.add(coulomb.HalfSpace(point=(0.0, 0.0), normal=(0.0, 1.0)))
>>> scene.contact(scene.attach(ball, coulomb.Point()), floor, mu=0.0, e=0.6)
>>> tr = scene.simulate(t_end=0.002, h=0.001)
>>> round(float(tr.v[-1, 1]), 12)  # Newton: v_n^+ = -e v_n^- (then one step of gravity)
1.79019

Every step solves, with M and the Jacobians frozen at ``q_k``,
``v_{k+1} = v_free + M^-1 G P`` and ``q_{k+1} = q_k + h v_{k+1}``; see :mod:`coulomb.trajectory`
for the record and its checks. A closed contact gets Newton's condition
``0 <= P_n ⊥ J_n v_{k+1} + e v_n^- >= 0`` (or Poisson's law, ``restitution="poisson"``); an
imminently closing one the gap term ``J_n v_{k+1} + g / h >= 0`` (it may close within the step,
not pass through), and when that step pushes, the contact records its approach velocity and
the next step gives back the rebound ``-e v_n^-`` whatever gap is left (a rotating body or a
turning normal leaves O(h^2)); the record is then consumed. The rebound is exact wherever in
the step the impact falls when no force acts during the step; under a force such as gravity
the approach is the velocity at the start of the landing step, so with ``e = 1`` each bounce
loses ``m g y_k`` (``y_k`` the height there, at most ``m g h |v_n^-|``: first order in h).
``locate_impacts=True`` finds the impact instant within the step for isolated impacts and
removes that loss.

:class:`Model` takes a user-defined model in generalized coordinates instead (``M(q)``,
``f(q, v, t)`` and :class:`GapContact` gap functions with Jacobians), stepped by a Python loop
around the same Rust contact solver.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, cast

import numpy as np

from . import _core, _validate
from .errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
    ProblemTooLargeError,
    ShapeError,
)
from .trajectory import Trajectory

__all__ = [
    "Body",
    "Box",
    "Disk",
    "GapContact",
    "HalfSpace",
    "Model",
    "Particle",
    "Point",
    "Polygon",
    "RigidBody2D",
    "RigidBody3D",
    "Scene",
    "Segment",
    "Shape",
    "Sphere",
]

Solver = Literal["nsgs", "lemke"]


def _vector(name: str, value: Any, n: int) -> list[float]:
    if value is None:
        raise ArgumentTypeError(f"{name} must be {n} real numbers, got None")
    arr = _validate.array(value, name, None).reshape(-1)
    if arr.shape != (n,):
        raise ShapeError(f"{name} must have {n} entries, got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} has a non-finite entry: {arr.tolist()}")
    return arr.tolist()


def _positive(name: str, value: float) -> float:
    return _validate.real(name, value, low=0.0, low_open=True, data=True)


def _steps(t_end: float, h: float) -> int:
    """``ceil(t_end / h)``, at least 1, at most :data:`coulomb._validate.MAX_COUNT`."""
    ratio = t_end / h
    if not ratio <= _validate.MAX_COUNT:
        raise InvalidParameterError(
            f"t_end / h = {ratio:.3g} steps, more than the limit of {_validate.MAX_COUNT}: "
            "use a larger h or a shorter t_end"
        )
    return max(1, math.ceil(ratio - 1e-9))


def _solver_options(
    dim: int, solver: Any, tol: Any, max_iter: Any, relaxation: Any, facets: Any
) -> tuple[Solver, float, int | None, float, int | None]:
    """A simulation's contact-solver options, checked as :func:`coulomb.contact.solve` checks
    them (the same messages, the same refusals)."""
    _validate.choice("solver", solver, ("nsgs", "lemke"),
                     "'nsgs' exact friction disk, 'lemke' polyhedral cone")
    if tol is None:
        tol = 1e-12 if solver == "nsgs" else 1e-9
    _, t, it, om, fa, _ = _validate.contact_options(dim, solver, tol, max_iter, relaxation,
                                                    facets, None)
    if fa is not None and dim == 2 and fa != 2:
        raise InvalidParameterError(
            f"facets must be 2 in 2D (the tangent directions +1 and -1, which are exact), "
            f"got {fa}")
    if fa is not None and dim == 3 and (fa < 4 or fa % 2):
        raise InvalidParameterError(
            f"facets must be even and at least 4 in 3D (tangent directions in +/- pairs), "
            f"got {fa}")
    return cast(Solver, solver), t, it, om, fa


def _dim(dim: Any) -> None:
    if isinstance(dim, (bool, np.bool_)) or not isinstance(dim, (int, np.integer)) or int(
        dim
    ) not in (2, 3):
        raise InvalidParameterError(f"dim must be 2 (planar) or 3 (spatial), got {dim!r}")


# --- bodies --------------------------------------------------------------------------------


@dataclass(eq=False)
class Body:
    """Base class of the bodies; use :class:`Particle`, :class:`RigidBody2D` or
    :class:`RigidBody3D`."""

    mass: float
    force: Sequence[float] | None = field(default=None, kw_only=True)
    name: str = field(default="", kw_only=True)

    kind = ""

    def _spec(self, dim: int) -> dict[str, Any]:
        raise NotImplementedError


@dataclass(eq=False)
class Particle(Body):
    """A point mass (kg) at ``position`` moving with ``velocity`` (``dim`` entries each)."""

    position: Sequence[float] = (0.0, 0.0)
    velocity: Sequence[float] | None = None

    kind = "particle"

    def _spec(self, dim: int) -> dict[str, Any]:
        v = self.velocity if self.velocity is not None else np.zeros(dim)
        return {
            "kind": "particle",
            "mass": _positive("mass", self.mass),
            "inertia": [],
            "q0": _vector("position", self.position, dim),
            "v0": _vector("velocity", v, dim),
        }


@dataclass(eq=False)
class RigidBody2D(Body):
    """A planar rigid body: mass (kg), central inertia (kg m^2), position ``(x, y)``, angle
    ``theta`` (rad), velocity ``(vx, vy)`` and angular velocity ``omega`` (rad/s)."""

    inertia: float = 1.0
    position: Sequence[float] = (0.0, 0.0)
    angle: float = 0.0
    velocity: Sequence[float] = (0.0, 0.0)
    angular_velocity: float = 0.0

    kind = "planar"

    def _spec(self, dim: int) -> dict[str, Any]:
        if dim != 2:
            raise InvalidParameterError("a RigidBody2D needs a planar scene (dim=2)")
        pos = _vector("position", self.position, 2)
        vel = _vector("velocity", self.velocity, 2)
        th = _vector("angle", [self.angle], 1)
        om = _vector("angular_velocity", [self.angular_velocity], 1)
        return {
            "kind": "planar",
            "mass": _positive("mass", self.mass),
            "inertia": [_positive("inertia", self.inertia)],
            "q0": pos + th,
            "v0": vel + om,
        }


@dataclass(eq=False)
class RigidBody3D(Body):
    """A spatial rigid body: mass (kg), body-frame inertia (3 principal moments or a symmetric
    positive definite 3x3 tensor, kg m^2), position, orientation as a quaternion
    ``(w, x, y, z)`` (normalised here), velocity and world-frame angular velocity."""

    inertia: Sequence[float] | np.ndarray = (1.0, 1.0, 1.0)
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    velocity: Sequence[float] = (0.0, 0.0, 0.0)
    angular_velocity: Sequence[float] = (0.0, 0.0, 0.0)

    kind = "spatial"

    def _spec(self, dim: int) -> dict[str, Any]:
        if dim != 3:
            raise InvalidParameterError("a RigidBody3D needs a spatial scene (dim=3)")
        j = np.asarray(self.inertia, dtype=np.float64)
        if j.shape == (3,):
            j = np.diag(j)
        if j.shape != (3, 3):
            raise ShapeError(f"inertia must be 3 moments or 3x3, got shape {j.shape}")
        if not np.all(np.isfinite(j)):
            raise NonFiniteError("inertia has a non-finite entry")
        if not np.allclose(j, j.T, rtol=1e-12, atol=0.0):
            raise InvalidParameterError("inertia must be symmetric")
        if np.linalg.eigvalsh(j).min() <= 0.0:
            raise InvalidParameterError("inertia must be positive definite")
        quat = np.asarray(_vector("orientation", self.orientation, 4))
        norm = float(np.linalg.norm(quat))
        if norm == 0.0:
            raise InvalidParameterError("orientation quaternion must be nonzero")
        return {
            "kind": "spatial",
            "mass": _positive("mass", self.mass),
            "inertia": j.reshape(-1).tolist(),
            "q0": _vector("position", self.position, 3) + (quat / norm).tolist(),
            "v0": _vector("velocity", self.velocity, 3)
            + _vector("angular_velocity", self.angular_velocity, 3),
        }


# --- shapes --------------------------------------------------------------------------------


@dataclass(eq=False)
class Shape:
    """Base class of contact shapes: body-frame points with a common radius."""

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        raise NotImplementedError


@dataclass(eq=False)
class Point(Shape):
    """A single body-frame point (default the centre of mass)."""

    offset: Sequence[float] | None = None

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        off = self.offset if self.offset is not None else np.zeros(dim)
        return [_vector("offset", off, dim)], 0.0


@dataclass(eq=False)
class Sphere(Shape):
    """A sphere (3D) or disk (2D) of ``radius`` (m) centred at a body-frame ``center``."""

    radius: float = 1.0
    center: Sequence[float] | None = None

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        c = self.center if self.center is not None else np.zeros(dim)
        r = float(self.radius)
        if not math.isfinite(r) or r < 0.0:
            raise InvalidParameterError(f"radius must be finite and >= 0, got {r}")
        return [_vector("center", c, dim)], r


Disk = Sphere


@dataclass(eq=False)
class Segment(Shape):
    """A segment's (rod's) two end points ``a``, ``b`` in the body frame, with a radius."""

    a: Sequence[float] = (-0.5, 0.0)
    b: Sequence[float] = (0.5, 0.0)
    radius: float = 0.0

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        r = float(self.radius)
        if not math.isfinite(r) or r < 0.0:
            raise InvalidParameterError(f"radius must be finite and >= 0, got {r}")
        return [_vector("a", self.a, dim), _vector("b", self.b, dim)], r


@dataclass(eq=False)
class Box(Shape):
    """A box's corners (4 in 2D, 8 in 3D) from its half extents, centred at the body origin."""

    half_extents: Sequence[float] = (0.5, 0.5)

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        he = np.asarray(_vector("half_extents", self.half_extents, dim))
        if np.any(he <= 0.0):
            raise InvalidParameterError(f"half_extents must be > 0, got {he.tolist()}")
        signs = np.array(np.meshgrid(*([[-1.0, 1.0]] * dim), indexing="ij")).reshape(dim, -1).T
        return (signs * he).tolist(), 0.0


@dataclass(eq=False)
class Polygon(Shape):
    """A polygon's (or point cloud's) body-frame vertices, with a radius."""

    vertices: Sequence[Sequence[float]] = ()
    radius: float = 0.0

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        if len(self.vertices) == 0:
            raise ShapeError("a polygon needs at least one vertex")
        r = float(self.radius)
        if not math.isfinite(r) or r < 0.0:
            raise InvalidParameterError(f"radius must be finite and >= 0, got {r}")
        return [_vector(f"vertex {i}", v, dim) for i, v in enumerate(self.vertices)], r


@dataclass(eq=False)
class HalfSpace:
    """A static half-space ``{x : n . (x - point) <= 0}``: its boundary is a floor, ramp or
    wall, ``normal`` pointing out of it (towards the bodies)."""

    point: Sequence[float] = (0.0, 0.0)
    normal: Sequence[float] = (0.0, 1.0)

    @classmethod
    def ramp(cls, angle_deg: float, dim: int = 2) -> HalfSpace:
        """A ramp through the origin descending towards +x at ``angle_deg``."""
        th = math.radians(angle_deg)
        if dim == 2:
            return cls((0.0, 0.0), (math.sin(th), math.cos(th)))
        return cls((0.0, 0.0, 0.0), (math.sin(th), 0.0, math.cos(th)))


# --- scene ---------------------------------------------------------------------------------


def _index(items: list[Any], obj: Any, what: str) -> int:
    for i, x in enumerate(items):
        if x is obj:
            return i
    raise InvalidParameterError(f"this {what} was not added to the scene")


class Scene:
    """A planar (``dim=2``) or spatial (``dim=3``) scene under uniform gravity (m/s^2)."""

    def __init__(self, dim: int = 2, gravity: Sequence[float] | None = None) -> None:
        _dim(dim)
        self.dim = int(dim)
        g = gravity if gravity is not None else [0.0] * (dim - 1) + [-9.81]
        self.gravity = _vector("gravity", g, dim)
        self.bodies: list[Body] = []
        self.half_spaces: list[HalfSpace] = []
        self.shapes: list[tuple[Body, Shape]] = []
        self.pairs: list[tuple[str, Any, Any, float, float]] = []

    def add(self, item: Body | HalfSpace) -> Any:
        """Adds a body or a half-space; returns it (use it as a handle)."""
        if isinstance(item, Body):
            item._spec(self.dim)  # checked now, before any work
            self.bodies.append(item)
        elif isinstance(item, HalfSpace):
            _vector("half-space point", item.point, self.dim)
            n = np.asarray(_vector("half-space normal", item.normal, self.dim))
            if not np.any(n != 0.0):
                raise InvalidParameterError("a half-space's normal must be nonzero")
            self.half_spaces.append(item)
        else:
            raise InvalidParameterError(f"cannot add {type(item).__name__} to a scene")
        return item

    def attach(self, body: Body, shape: Shape) -> Shape:
        """Attaches a contact shape to a body; returns the shape (a handle for contacts)."""
        _index(self.bodies, body, "body")
        if any(s is shape for _, s in self.shapes):
            raise InvalidParameterError("this shape is already attached to a body")
        shape._points(self.dim)
        self.shapes.append((body, shape))
        return shape

    def contact(self, shape: Shape, other: Shape | HalfSpace, mu: float = 0.0,
                e: float = 0.0) -> None:
        """Declares that ``shape`` may touch ``other`` (a half-space, or a sphere on another
        body), with friction coefficient ``mu >= 0`` and Newton restitution ``e`` in [0, 1]."""
        mu = _validate.real("mu", mu, low=0.0, data=True)
        e = _validate.real("e", e, low=0.0, high=1.0, data=True)
        a = _index([s for _, s in self.shapes], shape, "shape")
        if isinstance(other, HalfSpace):
            self.pairs.append(("half_space", a, _index(self.half_spaces, other, "half-space"),
                               mu, e))
            return
        b = _index([s for _, s in self.shapes], other, "shape")
        if not (isinstance(shape, Sphere) and isinstance(other, Sphere)):
            raise InvalidParameterError("shape-shape contacts are sphere vs sphere only")
        if self.shapes[a][0] is self.shapes[b][0]:
            raise InvalidParameterError("both spheres are on the same body")
        self.pairs.append(("sphere", a, b, mu, e))

    def contact_spheres(self, mu: float = 0.0, e: float = 0.0) -> None:
        """Lets every pair of spheres on different bodies touch, with friction coefficient
        ``mu >= 0`` and Newton restitution ``e`` in [0, 1], without declaring the pairs: the
        stepper finds the pairs near each other itself every step (a broad phase, a uniform
        grid over the spheres, O(N) per step). The spheres are the single-point shapes
        (:class:`Sphere`; a :class:`Point` counts as a sphere of radius 0). A pair also
        declared with :meth:`contact` keeps that declaration's ``mu`` and ``e``. Contact ids
        of these pairs are ``D + i B + j`` (``D`` declared candidates, ``B`` spheres, ``i < j``
        the spheres' indices in the order they were attached)."""
        mu = _validate.real("mu", mu, low=0.0, data=True)
        e = _validate.real("e", e, low=0.0, high=1.0, data=True)
        if any(p[0] == "spheres" for p in self.pairs):
            raise InvalidParameterError("contact_spheres was already called on this scene")
        self.pairs.append(("spheres", 0, 0, mu, e))

    def _spec(self) -> dict[str, Any]:
        bodies = []
        for b in self.bodies:
            spec = b._spec(self.dim)
            f = b.force if b.force is not None else np.zeros(self.dim)
            spec["force"] = _vector("force", f, self.dim)
            bodies.append(spec)
        shapes = []
        for body, shape in self.shapes:
            pts, r = shape._points(self.dim)
            shapes.append({"body": _index(self.bodies, body, "body"), "points": pts,
                           "radius": r})
        return {
            "dim": self.dim,
            "gravity": self.gravity,
            "bodies": bodies,
            "shapes": shapes,
            "half_spaces": [
                {"point": _vector("point", h.point, self.dim),
                 "normal": _vector("normal", h.normal, self.dim)}
                for h in self.half_spaces
            ],
            "pairs": [{"kind": k, "a": a, "b": b, "mu": mu, "e": e}
                      for k, a, b, mu, e in self.pairs],
        }

    def layout(self) -> list[tuple[slice, slice]]:
        """The slices of each body's coordinates and velocities in ``q`` and ``v``."""
        out = []
        iq = iv = 0
        for b in self.bodies:
            nq = {"particle": self.dim, "planar": 3, "spatial": 7}[b.kind]
            nv = {"particle": self.dim, "planar": 3, "spatial": 6}[b.kind]
            out.append((slice(iq, iq + nq), slice(iv, iv + nv)))
            iq, iv = iq + nq, iv + nv
        return out

    def simulate(
        self,
        t_end: float,
        h: float,
        solver: Solver = "nsgs",
        *,
        tol: float | None = None,
        max_iter: int | None = None,
        relaxation: float = 1.0,
        facets: int | None = None,
        gap_tolerance: float = 1e-9,
        warm_start: bool = True,
        fallback: bool = True,
        drift: Literal["none", "bias", "projection"] = "none",
        drift_bias: float = 0.2,
        restitution: Literal["newton", "poisson"] = "newton",
        record_every: int = 1,
        locate_impacts: bool = False,
    ) -> Trajectory:
        """Runs ``ceil(t_end / h)`` steps of the impulse time stepper from the initial state.

        Parameters
        ----------
        t_end, h : float
            Duration and time step (s), both > 0.
        solver : {"nsgs", "lemke"}
            The contact solver of every step: nonsmooth Gauss-Seidel on the exact friction disk
            (warm-started from the previous step's impulses of the same contacts) or the
            polyhedral-cone LCP by Lemke's method (``facets`` directions in 3D, default 8).
        tol : float, optional
            The contact solver's tolerance (default 1e-12 for NSGS, 1e-9 for Lemke).
        max_iter : int, optional
            NSGS sweeps (default 1000) or Lemke pivots (default ``max(1000, 50 n)``).
        relaxation : float
            NSGS relaxation in (0, 2).
        gap_tolerance : float
            A contact with gap at most this (m) is closed (restitution applies); above it, it is
            open and carries unknowns only if it could close within the step (gap term).
        warm_start : bool
            Start NSGS from the previous step's impulses.
        fallback : bool
            When NSGS misses its tolerance (it can stall on singular, strongly coupled W),
            also solve by the polyhedral Lemke (up to 32 contacts) or the robust mode
            (proximal Newton, above; NSGS then gets 100 sweeps first) and keep the answer with
            the smaller exact-disk error (such steps are marked in ``fallback``).
        drift : {"none", "bias", "projection"}
            The position-drift correction (a velocity-level step does not enforce
            ``g(q_{k+1}) >= 0`` exactly): none; a velocity bias, a closed contact with ``g < 0``
            getting ``J_n v_{k+1} + e v_n^- + drift_bias g / h >= 0`` (pushes a fraction
            ``drift_bias`` in (0, 1] of the penetration out per step, adding kinetic energy);
            or a post-step projection onto ``g >= 0`` by the M-smallest displacement over
            every nearby contact (velocities untouched; its size per step is in
            ``projection``), which never deepens the worst penetration and never raises the
            energy (a lift against gravity is paid from what the step dissipated). Measured on
            five balls stacked 2 mm aside toppling (h = 1e-3, 1 s): worst penetration 1.6e-4 m
            without, 3.6e-4 m with the bias (energy gained in 289 steps), 2.0e-5 m with the
            projection (no step gaining energy).
        restitution : {"newton", "poisson"}
            The impact law at closed contacts, with each pair's ``e``: Newton's velocity-level
            condition ``J_n v_{k+1} + e v_n^- >= 0``, or Poisson's (an impact phase on ``v_k``:
            compression until the normal velocity stops, then the normal restitution impulse
            ``e P_comp``, Coulomb friction acting in both phases: Routh's integration in
            impulse space for one contact, which never gains energy, the two phases solved as
            wholes for coupled contacts). They agree on a single frictionless impact. Newton's
            law with friction can gain energy (a rod at 45 deg striking at v = (0.6, -1),
            e = 1, sticking: +0.1125 J); Poisson's does not.
        locate_impacts : bool
            Locate isolated impacts within the step (every active contact open, one reaching
            zero gap first): the step follows its free path to the impact instant, applies the
            impact law there and finishes the step from it. With ``e = 1`` under gravity the
            apex energy is then kept bounce after bounce (the plain step loses ``m g y_k`` per
            bounce, ``y_k`` the height at the start of the landing step). Other steps are
            plain steps.
        record_every : int
            Keep the state only after every ``record_every``-th step (and after the last); a
            kept step's checks (status, error, residuals, violations) are the worst over the
            steps since the previous kept one, so no failure is lost, and the contact records
            are those of the kept steps (``contact_step`` is then the row in the step
            arrays). The records grow as the run goes; their size is checked against
            ``coulomb.memory_budget()`` and a run that would exceed it is refused
            (:class:`~coulomb.errors.ProblemTooLargeError`, saying which ``record_every``
            fits).

        Notes
        -----
        Counts are ints (``max_iter``, ``facets``, ``record_every``), ``t_end / h`` at most
        10^9 steps; options of the other solver are refused (``relaxation`` is NSGS's,
        ``facets`` Lemke's). Ctrl-C stops the run (``KeyboardInterrupt``).
        """
        t_end = _positive("t_end", t_end)
        h = _positive("h", h)
        steps = _steps(t_end, h)
        solver, tol, max_iter, relaxation, facets = _solver_options(
            self.dim, solver, tol, max_iter, relaxation, facets)
        gap_tolerance = _validate.real("gap_tolerance", gap_tolerance, low=0.0)
        warm_start = _validate.boolean("warm_start", warm_start)
        fallback = _validate.boolean("fallback", fallback)
        _validate.choice("drift", drift, ("none", "bias", "projection"), "drift correction")
        drift_bias = _validate.real("drift_bias", drift_bias, low=0.0, high=1.0, low_open=True)
        _validate.choice("restitution", restitution, ("newton", "poisson"), "impact law")
        record_every = _validate.count("record_every", record_every)
        locate_impacts = _validate.boolean("locate_impacts", locate_impacts)
        if not self.bodies:
            raise InvalidParameterError("the scene has no bodies")
        spec = self._spec()
        raw = _core.step_simulate(
            spec, h, steps, solver=solver, tol=tol, max_iter=max_iter, relaxation=relaxation,
            facets=facets, gap_tolerance=gap_tolerance, warm_start=warm_start,
            fallback=fallback, drift=drift, drift_bias=float(drift_bias),
            restitution=restitution, record_every=record_every,
            locate_impacts=locate_impacts,
        )
        tr = Trajectory._from_core(raw, scene=self, h=h, solver=solver,
                                   gap_tolerance=gap_tolerance, tol=tol)
        tr["record_every"] = record_every
        return tr


# --- user-defined models in generalized coordinates -----------------------------------------


def _numeric_jacobian(fun: Callable[[np.ndarray], Any], q: np.ndarray, rows: int) -> np.ndarray:
    """Central differences of ``fun`` at q, step ``1e-6 max(1, |q_i|)`` per coordinate."""
    jac = np.empty((rows, q.size))
    for i in range(q.size):
        d = 1e-6 * max(1.0, abs(q[i]))
        qp, qm = q.copy(), q.copy()
        qp[i] += d
        qm[i] -= d
        jac[:, i] = (np.atleast_1d(fun(qp)) - np.atleast_1d(fun(qm))).reshape(rows) / (2 * d)
    return jac


@dataclass(eq=False)
class GapContact:
    """A contact of a generalized-coordinate :class:`Model`: the gap ``g(q)`` (> 0 when
    separated), its normal Jacobian ``J_n(q) = dg/dq`` (``nv`` entries; central differences of
    ``gap`` when omitted), and for friction either the tangential Jacobian ``J_t(q)``
    (``(dim - 1, nv)``) or a tangential position ``s(q)`` (``dim - 1`` entries) whose central
    differences give it. ``mu >= 0`` and Newton's ``e`` in [0, 1]."""

    gap: Callable[[np.ndarray], float]
    normal_jacobian: Callable[[np.ndarray], Any] | None = None
    tangent_jacobian: Callable[[np.ndarray], Any] | None = None
    tangent_position: Callable[[np.ndarray], Any] | None = None
    mu: float = 0.0
    e: float = 0.0


class Model:
    r"""A model in generalized coordinates q (``v = dq/dt``, so ``nq = nv``):

    ``M(q) dv = f(q, v, t) dt + J_n^T dP_n + J_t^T dP_t``

    with the mass matrix ``mass_matrix`` (an SPD array or a callable ``M(q)``), the forces
    ``force(q, v, t)`` (default none) and the contacts (:class:`GapContact`). The same impulse
    step as :meth:`Scene.simulate`, run as a Python loop around the Rust contact solver
    (:func:`coulomb.contact.solve`). ``potential(q)`` (optional) adds the potential energy to
    the trajectory's total energy.
    """

    def __init__(
        self,
        dim: int,
        mass_matrix: Any,
        q0: Sequence[float],
        v0: Sequence[float] | None = None,
        force: Callable[[np.ndarray, np.ndarray, float], Any] | None = None,
        contacts: Sequence[GapContact] = (),
        potential: Callable[[np.ndarray], float] | None = None,
    ) -> None:
        _dim(dim)
        self.dim = int(dim)
        if q0 is None:
            raise ArgumentTypeError("q0 must be an array of real numbers, got None")
        q = _validate.array(q0, "q0", None).reshape(-1)
        self.q0 = np.asarray(_vector("q0", q, q.size))
        n = self.q0.size
        self.v0 = np.asarray(_vector("v0", v0 if v0 is not None else np.zeros(n), n))
        self.mass_matrix = mass_matrix
        self.force = force
        self.potential = potential
        for i, c in enumerate(contacts):
            if not isinstance(c, GapContact):
                raise ArgumentTypeError(f"contact {i} must be a GapContact, got {c!r}")
            _validate.real(f"contact {i}'s mu", c.mu, low=0.0)
            _validate.real(f"contact {i}'s e", c.e, low=0.0, high=1.0)
            if not callable(c.gap):
                raise ArgumentTypeError(f"contact {i}'s gap must be a function of q")
            if c.mu > 0 and c.tangent_jacobian is None and c.tangent_position is None:
                raise InvalidParameterError(
                    f"contact {i} has friction: give tangent_jacobian or tangent_position")
        self.contacts = list(contacts)
        self._mass(self.q0)  # checked before any work

    def _mass(self, q: np.ndarray) -> np.ndarray:
        m = self.mass_matrix(q) if callable(self.mass_matrix) else self.mass_matrix
        m = np.asarray(m, dtype=np.float64)
        n = q.size
        if m.shape != (n, n):
            raise ShapeError(f"M(q) must be {n} x {n}, got {m.shape}")
        if not np.all(np.isfinite(m)):
            raise NonFiniteError("M(q) has a non-finite entry")
        if not np.allclose(m, m.T, rtol=1e-10, atol=0.0):
            raise InvalidParameterError("M(q) must be symmetric")
        try:
            np.linalg.cholesky(m)
        except np.linalg.LinAlgError as exc:
            raise InvalidParameterError("M(q) must be positive definite") from exc
        return m

    def _frame(self, c: GapContact, q: np.ndarray) -> tuple[float, np.ndarray]:
        """The gap and the rows ``[J_n; J_t]`` (dim x nv) of one contact at q."""
        n = q.size
        i = next(k for k, x in enumerate(self.contacts) if x is c)
        try:
            g = float(c.gap(q))
        except (TypeError, ValueError) as exc:
            raise ArgumentTypeError(
                f"contact {i}'s gap function must return a real number: {exc}") from None
        if not math.isfinite(g):
            raise NonFiniteError(
                f"contact {i}'s gap function returned {g} at q = {q.tolist()}")
        rows = np.zeros((self.dim, n))
        try:
            rows[0] = (_validate.array(c.normal_jacobian(q), f"contact {i}'s normal_jacobian",
                                       None).reshape(n)
                       if c.normal_jacobian is not None else _numeric_jacobian(c.gap, q, 1)[0])
            if c.tangent_jacobian is not None:
                rows[1:] = _validate.array(c.tangent_jacobian(q),
                                           f"contact {i}'s tangent_jacobian",
                                           None).reshape(self.dim - 1, n)
            elif c.tangent_position is not None:
                rows[1:] = _numeric_jacobian(c.tangent_position, q, self.dim - 1)
        except ValueError as exc:
            if isinstance(exc, (ShapeError, InvalidParameterError)):
                raise
            raise ShapeError(f"contact {i}: the Jacobian rows must be {self.dim} x {n} "
                             f"(J_n: {n} entries, J_t: {self.dim - 1} x {n}): {exc}") from None
        if not np.all(np.isfinite(rows)):
            raise NonFiniteError(
                f"contact {i}'s Jacobian rows [J_n; J_t] have a non-finite entry at "
                f"q = {q.tolist()}")
        return g, rows

    def simulate(
        self,
        t_end: float,
        h: float,
        solver: Solver = "nsgs",
        *,
        tol: float | None = None,
        max_iter: int | None = None,
        facets: int | None = None,
        gap_tolerance: float = 1e-9,
        warm_start: bool = True,
        fallback: bool = True,
    ) -> Trajectory:
        """Runs ``ceil(t_end / h)`` impulse steps; options as :meth:`Scene.simulate`."""
        from . import contact as _contact

        t_end, h = _positive("t_end", t_end), _positive("h", h)
        steps = _steps(t_end, h)
        solver, tol, max_iter, _, facets = _solver_options(
            self.dim, solver, tol, max_iter, 1.0, facets)
        gap_tolerance = _validate.real("gap_tolerance", gap_tolerance, low=0.0)
        warm_start = _validate.boolean("warm_start", warm_start)
        fallback = _validate.boolean("fallback", fallback)
        row_bytes = 8 * (2 * self.q0.size + 16)
        if (steps + 1) * row_bytes > _core.memory_budget():
            raise ProblemTooLargeError(
                f"recording {steps + 1} states of {self.q0.size} coordinates needs about "
                f"{(steps + 1) * row_bytes} bytes, over the memory budget of "
                f"{_core.memory_budget()} bytes (coulomb.set_memory_budget raises it): "
                "simulate a shorter span per call")
        dim, nc = self.dim, len(self.contacts)
        q, v = self.q0.copy(), self.v0.copy()
        warm = np.zeros((nc, dim))
        approach = np.zeros(nc)
        landed = np.zeros(nc, dtype=bool)
        rec: dict[str, list[Any]] = {k: [] for k in (
            "t", "q", "v", "kinetic_energy", "potential_energy", "min_gap", "negative_gaps",
            "active", "status", "error", "scaled_error", "iterations", "momentum_residual",
            "min_normal_impulse", "cone_violation", "complementarity", "resumed", "fallback",
            "contact_step", "contact_id", "contact_impulse", "contact_velocity",
            "contact_approach", "contact_gap", "contact_closed", "load_power")}

        def push_state(t: float, m: np.ndarray, gaps: list[float]) -> None:
            rec["t"].append(t)
            rec["q"].append(q.copy())
            rec["v"].append(v.copy())
            rec["kinetic_energy"].append(0.5 * float(v @ m @ v))
            rec["potential_energy"].append(float(self.potential(q)) if self.potential else 0.0)
            rec["min_gap"].append(min(gaps, default=math.inf))
            rec["negative_gaps"].append(sum(g < -gap_tolerance for g in gaps))

        stopped = None
        m = self._mass(q)
        frames = [self._frame(c, q) for c in self.contacts]
        push_state(0.0, m, [g for g, _ in frames])
        for k in range(steps):
            t = k * h
            f = (np.asarray(self.force(q, v, t), dtype=np.float64).reshape(q.size)
                 if self.force else np.zeros(q.size))
            rec["load_power"].append(float(f @ v))
            v_free = v + h * np.linalg.solve(m, f)
            active = []
            for i, (g, rows) in enumerate(frames):
                vn_k, vn_free = float(rows[0] @ v), float(rows[0] @ v_free)
                # a contact owed the rebound of the impact the last step stopped stays active
                if g > gap_tolerance + 2 * h * max(0.0, -vn_k, -vn_free) and not landed[i]:
                    approach[i], landed[i], warm[i] = 0.0, False, 0.0
                    continue
                active.append((i, g, rows, vn_k, g <= gap_tolerance or bool(landed[i])))
            resumed = used_fallback = False
            v_next = v_free.copy()
            gp = np.zeros(q.size)
            status, err, iters, mn, cone, comp = "no_contact", 0.0, 0, 0.0, 0.0, 0.0
            serr = 0.0
            if active:
                G = np.vstack([rows for _, _, rows, _, _ in active])  # (dim na, nv)
                minv_gt = np.linalg.solve(m, G.T)
                W = G @ minv_gt
                W = 0.5 * (W + W.T)
                qc = G @ v_free
                used = []
                for a, (i, g, _, vn_k, closed) in enumerate(active):
                    if closed:
                        vminus = min(vn_k, approach[i], 0.0)
                        resumed = resumed or bool(landed[i])
                        qc[a * dim] += self.contacts[i].e * vminus
                        used.append(vminus)
                    else:
                        qc[a * dim] += g / h
                        used.append(vn_k)
                mus = np.array([self.contacts[i].mu for i, *_ in active])
                if np.all(qc[::dim] >= 0.0):
                    r = np.zeros(len(active) * dim)
                    status = "solved"
                else:
                    init = np.concatenate([warm[i] for i, *_ in active])
                    res = _contact.solve(W, qc, mus, dim=dim, method=solver, tol=tol,
                                         max_iter=max_iter, facets=facets,
                                         initial=init if (warm_start and solver == "nsgs")
                                         else None)
                    if not res.success and fallback and solver == "nsgs":
                        alt = _contact.solve(W, qc, mus, dim=dim, method="lemke",
                                             tol=max(tol, 1e-9))
                        if alt.scaled_error < res.scaled_error:
                            used_fallback = True
                            first_status, res = res.status, alt
                            if alt.scaled_error <= max(tol, 1e-9):
                                res["status"] = "solved"
                            elif alt.status == "solved":
                                # a polygon's answer (3D) that misses the exact cone
                                res["status"] = first_status
                    r = res.impulse.reshape(-1)
                    status, err, iters = res.status, res.error, res.iterations
                    serr = res.scaled_error
                    mn, cone = res.min_normal_impulse, res.cone_violation
                    comp = res.max_complementarity
                gp = G.T @ r
                v_next = v_free + minv_gt @ r
                for a, (i, g, rows, vn_k, closed) in enumerate(active):
                    p = r[a * dim:(a + 1) * dim]
                    warm[i] = p
                    # the impact record: made by an open contact that pushed, consumed by
                    # the next step, never replayed
                    landed[i] = not closed and p[0] > 0.0
                    approach[i] = min(vn_k, 0.0) if landed[i] else 0.0
                    rec["contact_step"].append(k)
                    rec["contact_id"].append(i)
                    rec["contact_impulse"].append(p.copy())
                    rec["contact_velocity"].append(rows @ v_next)
                    rec["contact_approach"].append(used[a])
                    rec["contact_gap"].append(g)
                    rec["contact_closed"].append(closed)
            mdv = m @ (v_next - v_free)
            scale = max(np.linalg.norm(gp), np.linalg.norm(m @ v_free),
                        np.linalg.norm(m @ v_next))
            res_norm = float(np.linalg.norm(mdv - gp))
            rec["momentum_residual"].append(res_norm / scale if scale > 1e-300 else res_norm)
            for key, val in (("active", len(active)), ("status", status), ("error", err),
                             ("scaled_error", serr),
                             ("iterations", iters), ("min_normal_impulse", mn),
                             ("cone_violation", cone), ("complementarity", comp),
                             ("resumed", resumed), ("fallback", used_fallback)):
                rec[key].append(val)
            v = v_next
            q = q + h * v
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                stopped = f"step {k} produced a non-finite state"
                break
            m = self._mass(q)
            frames = [self._frame(c, q) for c in self.contacts]
            push_state((k + 1) * h, m, [g for g, _ in frames])
        # f . v of the last state, for the step's energy E_h = T + V + (h/2) f . v (a stopped
        # run recorded one per state already: its last step's state was not kept)
        if stopped is None:
            f = (np.asarray(self.force(q, v, (len(rec["t"]) - 1) * h),
                            dtype=np.float64).reshape(q.size)
                 if self.force else np.zeros(q.size))
            rec["load_power"].append(float(f @ v))
        raw: dict[str, Any] = {"dim": dim, "stopped": stopped, "solve_time": float("nan")}
        for key, val in rec.items():
            if key in ("q", "v"):
                raw[key] = np.array(val, dtype=np.float64).reshape(len(val), q.size)
            elif key in ("contact_impulse", "contact_velocity"):
                raw[key] = np.array(val, dtype=np.float64).reshape(len(val), dim)
            elif key == "status":
                raw[key] = list(val)
            elif key in ("resumed", "fallback", "contact_closed"):
                raw[key] = np.array(val, dtype=bool)
            elif key in ("active", "iterations", "negative_gaps", "contact_step", "contact_id"):
                raw[key] = np.array(val, dtype=np.int64)
            else:
                raw[key] = np.array(val, dtype=np.float64)
        return Trajectory._from_core(raw, scene=None, h=h, solver=solver,
                                     gap_tolerance=gap_tolerance, tol=tol)
