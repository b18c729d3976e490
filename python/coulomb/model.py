r"""Scenes: bodies, contact shapes, half-spaces and contact pairs, simulated by the seed's
impulse time stepper (the whole loop runs in Rust, with the GIL released).

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
for the record and its checks.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from . import _core
from .errors import InvalidParameterError, NonFiniteError, ShapeError
from .trajectory import Trajectory

__all__ = [
    "Body",
    "Box",
    "Disk",
    "HalfSpace",
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
    arr = np.asarray(value, dtype=np.float64).reshape(-1) if value is not None else None
    if arr is None or arr.shape != (n,):
        got = None if arr is None else arr.shape
        raise ShapeError(f"{name} must have {n} entries, got shape {got}")
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} has a non-finite entry: {arr.tolist()}")
    return arr.tolist()


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise NonFiniteError(f"{name} must be finite, got {v}")
    if v <= 0.0:
        raise InvalidParameterError(f"{name} must be > 0, got {v}")
    return v


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
        if dim not in (2, 3):
            raise InvalidParameterError(f"dim must be 2 (planar) or 3 (spatial), got {dim}")
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
        mu, e = float(mu), float(e)
        if not (math.isfinite(mu) and mu >= 0.0):
            raise InvalidParameterError(f"mu must be finite and >= 0, got {mu}")
        if not (math.isfinite(e) and 0.0 <= e <= 1.0):
            raise InvalidParameterError(f"e must be in [0, 1], got {e}")
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
        """
        t_end = _positive("t_end", t_end)
        h = _positive("h", h)
        if solver not in ("nsgs", "lemke"):
            raise InvalidParameterError(
                f"unknown solver {solver!r}: expected 'nsgs' (exact friction disk) or 'lemke' "
                "(polyhedral cone)"
            )
        if tol is None:
            tol = 1e-12 if solver == "nsgs" else 1e-9
        tol = _positive("tol", tol)
        if not (0.0 < relaxation < 2.0):
            raise InvalidParameterError(f"relaxation must lie in (0, 2), got {relaxation}")
        if max_iter is not None and int(max_iter) < 1:
            raise InvalidParameterError(f"max_iter must be >= 1, got {max_iter}")
        gap_tolerance = float(gap_tolerance)
        if not (math.isfinite(gap_tolerance) and gap_tolerance >= 0.0):
            raise InvalidParameterError(f"gap_tolerance must be finite and >= 0, got "
                                        f"{gap_tolerance}")
        if not self.bodies:
            raise InvalidParameterError("the scene has no bodies")
        steps = max(1, math.ceil(t_end / h - 1e-9))
        spec = self._spec()
        raw = _core.step_simulate(
            spec, h, steps, solver=solver, tol=tol, max_iter=max_iter, relaxation=relaxation,
            facets=facets, gap_tolerance=gap_tolerance, warm_start=warm_start,
        )
        return Trajectory._from_core(raw, scene=self, h=h, solver=solver,
                                     gap_tolerance=gap_tolerance)
