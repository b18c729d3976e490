"""Contact shapes: the base class, and the solids of the geometry layer (capsules, cylinders,
cones, convex hulls, compounds; static triangle meshes and heightfields), whose contacts with
any other solid come from the narrow phase of dimforge's parry, corrected (``coulomb.geometry``
in Rust). Each is checked when it is made and again, with the Rust constructors' own checks
(a hull of coplanar points, a non-manifold mesh), when it is attached or added."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from ._arguments import _positive, _vector
from .errors import InvalidParameterError, ShapeError


def _pose(dim: int, center: Sequence[float] | None,
          orientation: float | Sequence[float] | None) -> list[float]:
    """A solid's pose in its body's frame: ``center`` (default the origin) and
    ``orientation`` (2D: an angle in rad; 3D: a quaternion ``(w, x, y, z)``, normalised)."""
    c = _vector("center", center if center is not None else [0.0] * dim, dim)
    if dim == 2:
        th = 0.0 if orientation is None else orientation
        if isinstance(th, (Sequence, np.ndarray)):
            raise ShapeError("a 2D orientation is one angle (rad)")
        return c + _vector("orientation", [th], 1)
    quat = np.asarray(_vector("orientation", orientation if orientation is not None
                              else (1.0, 0.0, 0.0, 0.0), 4))
    norm = float(np.linalg.norm(quat))
    if norm == 0.0:
        raise InvalidParameterError("orientation quaternion must be nonzero")
    return c + (quat / norm).tolist()


@dataclass(eq=False)
class Shape:
    """Base class of contact shapes. The point shapes (:class:`~coulomb.Point`,
    :class:`~coulomb.Sphere`, :class:`~coulomb.Segment`, :class:`~coulomb.Box`,
    :class:`~coulomb.Polygon`) are body-frame points with a common radius (their contacts with
    half-spaces and between spheres are computed in closed form); every shape with a volume
    is also a solid, which touches any other solid."""

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        """body-frame points with a radius: the contact points of a point shape, or points
        to draw and bound a solid."""
        raise NotImplementedError

    def _solid(self, dim: int) -> dict[str, Any] | None:
        """the solid's description for the stepper (kind, data, pose), or None."""
        return None

    #: whether its contacts with half-spaces use its points (the point shapes).
    _point_form = True


def _check_solid(spec: dict[str, Any], dim: int) -> dict[str, Any]:
    """runs the Rust constructors' checks on a solid's description (errors as
    :mod:`coulomb.errors` exceptions)."""
    _core.solid_check(spec, dim)
    return spec


@dataclass(eq=False)
class Capsule(Shape):
    """The points within ``radius`` (> 0) of the segment ``[a, b]`` (body frame, ``dim``
    entries each; ``a == b`` is a sphere)."""

    a: Sequence[float] = (-0.5, 0.0)
    b: Sequence[float] = (0.5, 0.0)
    radius: float = 0.1

    _point_form = False

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        return [_vector("a", self.a, dim), _vector("b", self.b, dim)], _positive(
            "radius", self.radius)

    def _solid(self, dim: int) -> dict[str, Any]:
        pts, r = self._points(dim)
        return {"kind": "capsule", "a": pts[0], "b": pts[1], "radius": r,
                "pose": _pose(dim, None, None)}


@dataclass(eq=False)
class _Round(Shape):
    half_height: float = 0.5
    radius: float = 0.1
    center: Sequence[float] | None = None
    orientation: Sequence[float] | None = None

    _point_form = False
    _kind = ""

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        if dim != 3:
            raise InvalidParameterError(f"a {type(self).__name__} needs a spatial scene (dim=3)")
        hh = _positive("half_height", self.half_height)
        r = _positive("radius", self.radius)
        pose = _pose(3, self.center, self.orientation)
        rot = _rotation(pose[3:])
        ring = [[r * math.cos(a), y, r * math.sin(a)]
                for y in (-hh, hh) for a in np.linspace(0.0, 2 * math.pi, 12, endpoint=False)]
        if self._kind == "cone":
            ring = [*ring[:12], [0.0, hh, 0.0]]
        pts = (np.asarray(ring) @ rot.T + np.asarray(pose[:3])).tolist()
        return pts, 0.0

    def _solid(self, dim: int) -> dict[str, Any]:
        self._points(dim)
        return {"kind": self._kind, "half_height": float(self.half_height),
                "radius": float(self.radius), "pose": _pose(3, self.center, self.orientation)}


@dataclass(eq=False)
class Cylinder(_Round):
    """A cylinder of ``radius`` and half height ``half_height`` (both > 0) whose axis is the
    y axis of its frame, placed in the body frame at ``center`` turned by ``orientation`` (a
    quaternion ``(w, x, y, z)``); spatial scenes. A flat end touches at the 32 corners of
    the regular polygon inscribed in its circle."""

    _kind = "cylinder"


@dataclass(eq=False)
class Cone(_Round):
    """A cone of base ``radius`` and half height ``half_height`` along its frame's y axis (apex
    at ``y = +half_height``, base disk at ``-half_height``), placed like :class:`Cylinder`;
    the base touches like a cylinder's end."""

    _kind = "cone"


def _rotation(quat: Sequence[float]) -> np.ndarray:
    w, x, y, z = quat
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


@dataclass(eq=False)
class ConvexHull(Shape):
    """The convex hull of body-frame ``points`` (3D: not all on one plane; 2D: not all on one
    line, a convex polygon)."""

    points: Sequence[Sequence[float]] = ()

    _point_form = False

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        if len(self.points) < dim + 1:
            raise ShapeError(f"a convex hull needs at least {dim + 1} points in {dim}D")
        return [_vector(f"point {i}", p, dim) for i, p in enumerate(self.points)], 0.0

    def _solid(self, dim: int) -> dict[str, Any]:
        pts, _ = self._points(dim)
        return {"kind": "convex_hull", "points": pts, "pose": _pose(dim, None, None)}


@dataclass(eq=False)
class Compound(Shape):
    """The union of convex ``parts``, each ``(shape, center, orientation)`` in the body frame
    (``center``, ``orientation`` may be None; 3D: a quaternion ``(w, x, y, z)``, 2D: an angle
    in rad); the parts are spheres (disks), boxes, capsules, segments, convex polygons or
    hulls, and in 3D cylinders and cones."""

    parts: Sequence[tuple[Shape, Sequence[float] | None, Any]] = ()

    _point_form = False

    def _points(self, dim: int) -> tuple[list[list[float]], float]:
        if len(self.parts) == 0:
            raise ShapeError("a compound needs at least one part")
        out: list[list[float]] = []
        for k, part in enumerate(self.parts):
            if not (isinstance(part, tuple) and len(part) == 3):
                raise ShapeError(f"compound part {k} must be (shape, center, orientation)")
            shape, center, orientation = part
            if not isinstance(shape, Shape):
                raise InvalidParameterError(f"compound part {k} is not a shape")
            pose = _pose(dim, center, orientation)
            pts, _ = shape._points(dim)
            rot = _rotation(pose[3:]) if dim == 3 else _rotation2(pose[2])
            out += (np.asarray(pts) @ rot.T + np.asarray(pose[:dim])).tolist()
        return out, 0.0

    def _solid(self, dim: int) -> dict[str, Any]:
        self._points(dim)
        parts = []
        for k, (shape, center, orientation) in enumerate(self.parts):
            spec = shape._solid(dim)
            if spec is None or spec["kind"] == "compound":
                raise InvalidParameterError(
                    f"compound part {k} ({type(shape).__name__}) is not a convex solid")
            outer = _pose(dim, center, orientation)
            if dim == 2:
                rot2 = _rotation2(outer[2])
                c = (rot2 @ np.asarray(spec["pose"][:2]) + np.asarray(outer[:2])).tolist()
                spec["pose"] = [*c, outer[2] + spec["pose"][2]]
            else:
                inner = _rotation(spec["pose"][3:])
                rot = _rotation(outer[3:])
                # the part's own pose composed into the compound's frame
                c = (rot @ np.asarray(spec["pose"][:3]) + np.asarray(outer[:3])).tolist()
                spec["pose"] = c + _quaternion(rot @ inner)
            parts.append(spec)
        return {"kind": "compound", "parts": parts, "pose": _pose(dim, None, None)}


def _rotation2(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _quaternion(r: np.ndarray) -> list[float]:
    """the unit quaternion ``(w, x, y, z)`` of a rotation matrix (Shepperd's method)."""
    t = np.trace(r)
    if t > 0:
        s = 2.0 * math.sqrt(t + 1.0)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0] * 4
        q[0] = (r[k, j] - r[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (r[j, i] + r[i, j]) / s
        q[1 + k] = (r[k, i] + r[i, k]) / s
    n = math.sqrt(sum(x * x for x in q))
    return [x / n for x in q]


@dataclass(eq=False)
class StaticSolid:
    """Base class of the static solids (added to a scene with ``scene.add``, fixed in the
    world): :class:`TriangleMesh`, :class:`Heightfield` (3D), :class:`Polyline` (2D)."""

    position: Sequence[float] = field(default=(0.0, 0.0, 0.0), kw_only=True)

    def _solid(self, dim: int) -> dict[str, Any]:
        raise NotImplementedError


@dataclass(eq=False)
class TriangleMesh(StaticSolid):
    """A static triangle mesh (spatial scenes): world-frame ``vertices`` (``n x 3``, shifted by
    ``position``) and ``triangles`` (``m x 3`` vertex indices), each wound counter-clockwise
    seen from the side bodies touch, consistently, with no triangle of zero area and no edge
    shared by more than two triangles."""

    vertices: Sequence[Sequence[float]] = ()
    triangles: Sequence[Sequence[int]] = ()

    def _solid(self, dim: int) -> dict[str, Any]:
        if dim != 3:
            raise InvalidParameterError("a TriangleMesh needs a spatial scene (dim=3)")
        v = np.asarray(self.vertices, dtype=np.float64)
        t = np.asarray(self.triangles)
        if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] < 3:
            raise ShapeError(f"vertices must be n x 3 (n >= 3), got shape {v.shape}")
        if t.ndim != 2 or t.shape[1] != 3 or t.shape[0] < 1:
            raise ShapeError(f"triangles must be m x 3 (m >= 1), got shape {t.shape}")
        if not np.issubdtype(t.dtype, np.integer) or t.min() < 0:
            raise InvalidParameterError("triangles must hold vertex indices (ints >= 0)")
        return {"kind": "triangle_mesh", "vertices": v.tolist(),
                "triangles": t.astype(np.int64).tolist(),
                "pose": [*_vector("position", self.position, 3), 1.0, 0.0, 0.0, 0.0]}


@dataclass(eq=False)
class Polyline(StaticSolid):
    """A static polyline (planar scenes: a terrain, a bin's profile): world-frame ``vertices``
    (``n x 2``, n >= 2, shifted by ``position``), no segment of zero length. Bodies touch it
    from either side; a contact on a segment takes the segment's normal. A shape of no
    thickness (a :class:`Segment` without radius) resting on it has no defined normal (both
    sides touch): give it a radius."""

    vertices: Sequence[Sequence[float]] = ()
    position: Sequence[float] = field(default=(0.0, 0.0), kw_only=True)

    def _solid(self, dim: int) -> dict[str, Any]:
        if dim != 2:
            raise InvalidParameterError(
                "a Polyline needs a planar scene (dim=2); in 3D use a TriangleMesh")
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 2:
            raise ShapeError(f"vertices must be n x 2 (n >= 2), got shape {v.shape}")
        return {"kind": "polyline", "vertices": v.tolist(),
                "pose": [*_vector("position", self.position, 2), 0.0]}


@dataclass(eq=False)
class Heightfield(StaticSolid):
    """A static heightfield (spatial scenes, z up): ``heights`` (``rows x cols``, at least
    2 x 2, row i at ``y``, column j at ``x``) over the rectangle of side ``size = (sx, sy)``
    centred at ``position``; the height at a grid point is ``position[2] + heights[i, j]``."""

    heights: Any = ((0.0, 0.0), (0.0, 0.0))
    size: Sequence[float] = (1.0, 1.0)

    def _solid(self, dim: int) -> dict[str, Any]:
        if dim != 3:
            raise InvalidParameterError("a Heightfield needs a spatial scene (dim=3)")
        h = np.asarray(self.heights, dtype=np.float64)
        if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
            raise ShapeError(f"heights must be rows x cols, at least 2 x 2, got {h.shape}")
        sx, sy = _vector("size", self.size, 2)
        # the geometry layer's heightfield spans its frame's x-z plane with heights along y:
        # turned by +90 degrees about x (y -> z, z -> -y), rows along -y
        c = math.sqrt(0.5)
        return {"kind": "heightfield", "rows": int(h.shape[0]), "cols": int(h.shape[1]),
                "heights": h[::-1].reshape(-1).tolist(), "scale": [sx, 1.0, sy],
                "pose": [*_vector("position", self.position, 3), c, c, 0.0, 0.0]}
