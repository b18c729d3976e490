"""The bodies of a scene (particles, planar and spatial rigid bodies), its point shapes (sets of
body-frame points with a radius: :class:`Point`, :class:`Sphere`/:class:`Disk`,
:class:`Segment`, :class:`Box`, :class:`Polygon`) and the static :class:`HalfSpace`. They are
re-exported by :mod:`coulomb.model`, where :class:`~coulomb.model.Scene` assembles them."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._arguments import _positive, _vector
from ._solids import Shape, _pose
from .errors import InvalidParameterError, NonFiniteError, ShapeError

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
        v = self.velocity if self.velocity is not None else [0.0] * dim
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
        moments = _positive_moments(self.inertia)
        quat = _vector("orientation", self.orientation, 4) if moments is not None else []
        if moments is not None and _unit_axis(quat):
            # principal moments and an exactly unit quaternion: every check below holds by
            # construction, and the spec is the same to the bit
            a, b, c = moments
            return {
                "kind": "spatial",
                "mass": _positive("mass", self.mass),
                "inertia": [a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c],
                "q0": _vector("position", self.position, 3) + quat,
                "v0": _vector("velocity", self.velocity, 3)
                + _vector("angular_velocity", self.angular_velocity, 3),
            }
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
        given = np.asarray(_vector("orientation", self.orientation, 4))
        norm = float(np.linalg.norm(given))
        if norm == 0.0:
            raise InvalidParameterError("orientation quaternion must be nonzero")
        return {
            "kind": "spatial",
            "mass": _positive("mass", self.mass),
            "inertia": j.reshape(-1).tolist(),
            "q0": _vector("position", self.position, 3) + (given / norm).tolist(),
            "v0": _vector("velocity", self.velocity, 3)
            + _vector("angular_velocity", self.angular_velocity, 3),
        }


def _positive_moments(inertia: Any) -> tuple[float, float, float] | None:
    """three finite positive principal moments given as Python floats, or None (then the
    general checks run)."""
    if type(inertia) not in (tuple, list) or len(inertia) != 3:
        return None
    if all(type(x) is float and math.isfinite(x) and x > 0.0 for x in inertia):
        return (inertia[0], inertia[1], inertia[2])
    return None


def _unit_axis(quat: list[float]) -> bool:
    """whether a quaternion is +-1 on one entry and 0 on the others (exactly of unit norm,
    so normalising it changes no bit)."""
    return sorted(abs(x) for x in quat) == [0.0, 0.0, 0.0, 1.0]


# --- shapes --------------------------------------------------------------------------------


@dataclass(eq=False)
class Point(Shape):
    """A single body-frame point (default the centre of mass)."""

    offset: Sequence[float] | None = None

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        off = self.offset if self.offset is not None else [0.0] * dim
        return [_vector("offset", off, dim)], 0.0


@dataclass(eq=False)
class Sphere(Shape):
    """A sphere (3D) or disk (2D) of ``radius`` (m) centred at a body-frame ``center``."""

    radius: float = 1.0
    center: Sequence[float] | None = None

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        c = self.center if self.center is not None else [0.0] * dim
        r = float(self.radius)
        if not math.isfinite(r) or r < 0.0:
            raise InvalidParameterError(f"radius must be finite and >= 0, got {r}")
        return [_vector("center", c, dim)], r

    def _solid(self, dim: int) -> dict[str, Any] | None:
        pts, r = self._points(dim)
        if r == 0.0:
            return None
        return {"kind": "sphere", "radius": r, "pose": _pose(dim, pts[0], None)}


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

    def _solid(self, dim: int) -> dict[str, Any] | None:
        pts, r = self._points(dim)
        pose = _pose(dim, None, None)
        if r > 0.0:
            return {"kind": "capsule", "a": pts[0], "b": pts[1], "radius": r, "pose": pose}
        if dim == 2:
            return {"kind": "segment", "a": pts[0], "b": pts[1], "pose": pose}
        return None


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

    def _solid(self, dim: int) -> dict[str, Any] | None:
        he = _vector("half_extents", self.half_extents, dim)
        self._points(dim)
        return {"kind": "box", "half_extents": he, "pose": _pose(dim, None, None)}


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

    def _solid(self, dim: int) -> dict[str, Any] | None:
        pts, r = self._points(dim)
        if r > 0.0 or len(pts) < dim + 1:
            return None
        return {"kind": "convex_hull", "points": pts, "pose": _pose(dim, None, None)}


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
