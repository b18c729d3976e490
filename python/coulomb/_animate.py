"""Moving pictures of a simulated :class:`~coulomb.Scene`: its bodies' shapes and its
half-spaces drawn at the trajectory's states, in 2D (patches) or 3D (mplot3d), written to GIF
or MP4 or shown inline in Jupyter (matplotlib's animation, the ``plot`` extra).

What is drawn, per shape attached to a body (each body in its own colour, ``C0``, ``C1``, ...):
a :class:`~coulomb.Sphere` as a disk (2D) or a wireframe sphere (3D) with a radius line that
turns with the body, a :class:`~coulomb.Segment` as a line (with its end disks when it has a
radius), a :class:`~coulomb.Box` as its outline (2D: a filled rectangle; 3D: its 12 edges), a
:class:`~coulomb.Polygon` as a filled polygon (2D) or its vertices (3D), a
:class:`~coulomb.Point` as a dot, a :class:`~coulomb.Capsule` as a :class:`~coulomb.Segment`
with a radius, a 2D :class:`~coulomb.ConvexHull` as a filled polygon, the other solids
(cylinder, cone, 3D hull, compound) as dots at points of their surface (static meshes and
heightfields are not drawn); a body without a shape as a dot at its centre of mass. A
:class:`~coulomb.HalfSpace` is its boundary line with the solid side shaded (2D) or a shaded
patch of its plane (3D).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._extras import require
from .errors import CoulombError, InvalidParameterError

if TYPE_CHECKING:
    from .model import Scene
    from .trajectory import Trajectory

__all__ = ["SceneAnimation", "WriterUnavailableError", "animate"]

#: the fill of a half-space's solid side and the colour of its boundary.
HALF_SPACE_FILL = (0.82, 0.82, 0.82)
HALF_SPACE_EDGE = (0.35, 0.35, 0.35)


class WriterUnavailableError(CoulombError, RuntimeError):
    """The movie writer a file type needs (ffmpeg for MP4) is not installed."""


# --- poses ---------------------------------------------------------------------------------


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a quaternion ``(w, x, y, z)`` (normalised here)."""
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def poses(scene: Scene, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each body's position and rotation matrix at one state ``q``."""
    dim = scene.dim
    out = []
    for body, (sq, _) in zip(scene.bodies, scene.layout(), strict=True):
        qb = np.asarray(q[sq], dtype=np.float64)
        if body.kind == "planar":
            c, s = math.cos(qb[2]), math.sin(qb[2])
            out.append((qb[:2], np.array([[c, -s], [s, c]])))
        elif body.kind == "spatial":
            out.append((qb[:3], _quat_matrix(qb[3:7])))
        else:
            out.append((qb[:dim], np.eye(dim)))
    return out


# --- the frame geometry (pure numpy: what each frame shows) --------------------------------


def _box_order_2d(pts: np.ndarray) -> np.ndarray:
    """The 4 corners of a 2D box (meshgrid order) in order around the rectangle."""
    return pts[[0, 2, 3, 1]]


def _box_edges_3d() -> list[tuple[int, int]]:
    """The 12 edges of a box's 8 corners in meshgrid order (corners differing in one sign)."""
    return [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]


def _clip_halfplane(poly: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """The part of a convex polygon (2D or 3D vertices) with ``normal . (x - point) <= 0``
    (Sutherland-Hodgman against one line or plane)."""
    out: list[np.ndarray] = []
    d = (poly - point) @ normal
    for i in range(len(poly)):
        a, b, da, db = poly[i], poly[(i + 1) % len(poly)], d[i], d[(i + 1) % len(poly)]
        if da <= 0:
            out.append(a)
        if (da < 0 < db) or (db < 0 < da):
            out.append(a + (b - a) * (da / (da - db)))
    return np.array(out).reshape(-1, poly.shape[1])


def _plane_patch(point: np.ndarray, normal: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """The part of the plane ``n . (x - point) = 0`` inside the box ``limits`` (3 x 2): a
    square of the plane around the projection of the box's middle, covering the box, clipped
    by the box's six faces (empty when the plane misses the box)."""
    n = normal / np.linalg.norm(normal)
    mid = limits.mean(axis=1)
    centre = mid - ((mid - point) @ n) * n
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    half = float(np.linalg.norm(limits[:, 1] - limits[:, 0]))
    poly = np.array([centre + half * (su * u + sw * w)
                     for su, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    for axis in range(3):
        for side, sign in ((1, 1.0), (0, -1.0)):  # x <= high, then -x <= -low
            if len(poly) < 3:
                return poly
            face = np.zeros(3)
            face[axis] = limits[axis, side]
            poly = _clip_halfplane(poly, face, sign * np.eye(3)[axis])
    return poly


def world_points(scene: Scene, q: np.ndarray) -> list[tuple[int, Any, np.ndarray, float]]:
    """Per attached shape: body index, shape, world-frame points (``k x dim``), radius."""
    from .model import Box

    pose = poses(scene, q)
    index = {id(b): i for i, b in enumerate(scene.bodies)}
    out = []
    for body, shape in scene.shapes:
        i = index[id(body)]
        body_pts, r = shape._points(scene.dim)
        pts = np.asarray(body_pts, dtype=np.float64)
        if isinstance(shape, Box) and scene.dim == 2:
            pts = _box_order_2d(pts)
        x, rot = pose[i]
        out.append((i, shape, x + pts @ rot.T, float(r)))
    return out


def _scene_of(tr: Trajectory) -> Scene:
    """The scene a trajectory simulated (a generalized-coordinate Model has none to draw)."""
    if tr.scene is None:
        raise TypeError(
            "animate() draws a Scene's bodies; a generalized-coordinate Model has no geometry "
            "to draw: plot its coordinates against time with Trajectory.plot()")
    return tr.scene


def auto_limits(tr: Trajectory, states: np.ndarray, margin: float = 0.1) -> np.ndarray:
    """``dim x 2`` axis limits holding every shape (points and radii) and every body centre
    over ``states``, and each half-space's reference point, widened by ``margin`` of the
    largest extent on each side."""
    scene = _scene_of(tr)
    lo = np.full(scene.dim, np.inf)
    hi = np.full(scene.dim, -np.inf)
    for k in states:
        for x, _ in poses(scene, tr.q[k]):
            lo, hi = np.minimum(lo, x), np.maximum(hi, x)
        for _, _, pts, r in world_points(scene, tr.q[k]):
            lo = np.minimum(lo, pts.min(axis=0) - r)
            hi = np.maximum(hi, pts.max(axis=0) + r)
    for hs in scene.half_spaces:
        p = np.asarray(hs.point, dtype=np.float64)
        lo, hi = np.minimum(lo, p), np.maximum(hi, p)
    span = float(np.max(hi - lo))
    pad = margin * span if span > 0 else 1.0
    return np.column_stack([lo - pad, hi + pad])


# --- drawing -------------------------------------------------------------------------------


def _title_text(title: bool | str, t: float) -> str:
    if title is True:
        return f"t = {t:.3f} s"
    if isinstance(title, str):
        return title.format(t=t)
    return ""


class SceneAnimation:
    """A trajectory's scene drawn frame by frame.

    ``states`` are the trajectory rows shown, ``figure`` and ``ax`` the matplotlib figure and
    axes (a plain Agg :class:`~matplotlib.figure.Figure`, not registered with pyplot).
    :meth:`draw` shows one frame, :meth:`rgba` renders one to pixels, :meth:`save` writes a
    GIF, MP4 or HTML file; in Jupyter the object shows itself as an interactive player
    (``to_jshtml``).
    """

    def __init__(self, tr: Trajectory, states: np.ndarray, fps: float, limits: np.ndarray,
                 title: bool | str, figsize: tuple[float, float], dpi: float) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.trajectory = tr
        self.scene: Scene = _scene_of(tr)
        self.states = states
        self.fps = float(fps)
        self.limits = limits
        self.title = title
        self.figure = Figure(figsize=figsize, dpi=dpi)
        self.canvas: Any = FigureCanvasAgg(self.figure)
        self.ax: Any
        dim = self.scene.dim
        if dim == 2:
            self.ax = self.figure.add_subplot()
            self.ax.set_aspect("equal", adjustable="box")
        else:
            self.ax = self.figure.add_subplot(projection="3d")
            self.ax.set_zlim(*limits[2])
            self.ax.set_zlabel("z [m]")
            self.ax.set_box_aspect(tuple(limits[:, 1] - limits[:, 0]))
        self.ax.set_xlim(*limits[0])
        self.ax.set_ylim(*limits[1])
        self.ax.set_xlabel("x [m]")
        self.ax.set_ylabel("y [m]")
        self._moving: list[Any] = []
        self._draw_half_spaces()
        self._animation: Any = None

    def __len__(self) -> int:
        return len(self.states)

    # -- static: half-spaces ------------------------------------------------------------------

    def _draw_half_spaces(self) -> None:
        lim = self.limits
        for hs in self.scene.half_spaces:
            p = np.asarray(hs.point, dtype=np.float64)
            n = np.asarray(hs.normal, dtype=np.float64)
            n = n / np.linalg.norm(n)
            if self.scene.dim == 2:
                from matplotlib.patches import Polygon

                box = np.array([[lim[0, 0], lim[1, 0]], [lim[0, 1], lim[1, 0]],
                                [lim[0, 1], lim[1, 1]], [lim[0, 0], lim[1, 1]]])
                solid = _clip_halfplane(box, p, n)
                if len(solid) >= 3:
                    self.ax.add_patch(Polygon(solid, closed=True, facecolor=HALF_SPACE_FILL,
                                              edgecolor="none", zorder=0))
                d = np.array([-n[1], n[0]])
                reach = 2.0 * float(np.max(lim[:, 1] - lim[:, 0])) + float(
                    np.linalg.norm(p - lim.mean(axis=1)))
                line = np.array([p - reach * d, p + reach * d])
                self.ax.plot(line[:, 0], line[:, 1], color=HALF_SPACE_EDGE, lw=1.5, zorder=1)
            else:
                from mpl_toolkits.mplot3d.art3d import (  # type: ignore[import-untyped]
                    Poly3DCollection,
                )

                patch = _plane_patch(p, n, lim)
                if len(patch) < 3:
                    continue
                self.ax.add_collection3d(Poly3DCollection(
                    [patch], facecolor=HALF_SPACE_FILL, edgecolor=HALF_SPACE_EDGE, alpha=0.5))

    # -- moving: bodies -----------------------------------------------------------------------

    def draw(self, frame: int) -> list[Any]:
        """Draws frame ``frame`` (trajectory row ``states[frame]``); returns its artists."""
        for artist in self._moving:
            artist.remove()
        k = int(self.states[frame])
        q = self.trajectory.q[k]
        if self.scene.dim == 2:
            self._moving = self._draw_2d(q)
        else:
            self._moving = self._draw_3d(q)
        text = _title_text(self.title, float(self.trajectory.t[k]))
        self.ax.set_title(text)
        return self._moving

    def _draw_2d(self, q: np.ndarray) -> list[Any]:
        from matplotlib.patches import Circle, Polygon

        from .model import Box, Capsule, ConvexHull, Segment, Sphere
        from .model import Polygon as PolygonShape

        ax = self.ax
        arts: list[Any] = []
        shaped = set()
        for i, shape, pts, r in world_points(self.scene, q):
            shaped.add(i)
            color = f"C{i % 10}"
            if isinstance(shape, Sphere) and r > 0:
                c = pts[0]
                arts.append(ax.add_patch(Circle(c, r, facecolor=color, edgecolor="k", lw=1.0,
                                                zorder=3)))
                rot = poses(self.scene, q)[i][1]
                tip = c + rot @ np.array([r, 0.0])
                arts += ax.plot([c[0], tip[0]], [c[1], tip[1]], color="k", lw=1.0, zorder=4)
            elif isinstance(shape, (Box, PolygonShape, ConvexHull)) and len(pts) >= 3:
                arts.append(ax.add_patch(Polygon(pts, closed=True, facecolor=color,
                                                 edgecolor="k", lw=1.0, zorder=3)))
                for c in pts if r > 0 else ():
                    arts.append(ax.add_patch(Circle(c, r, facecolor=color, edgecolor="k",
                                                    lw=0.5, zorder=3)))
            elif isinstance(shape, (Segment, PolygonShape, Capsule)) and len(pts) >= 2:
                arts += ax.plot(pts[:, 0], pts[:, 1], color=color, lw=3.0, zorder=3,
                                solid_capstyle="round")
                for c in pts if r > 0 else ():
                    arts.append(ax.add_patch(Circle(c, r, facecolor=color, edgecolor="k",
                                                    lw=0.5, zorder=3)))
            else:  # a Point, a sphere of radius 0
                arts += ax.plot(pts[:, 0], pts[:, 1], "o", color=color, mec="k", ms=6,
                                zorder=4)
        for i, (x, _) in enumerate(poses(self.scene, q)):
            if i not in shaped:
                arts += ax.plot([x[0]], [x[1]], "o", color=f"C{i % 10}", mec="k", ms=6,
                                zorder=4)
        return arts

    def _draw_3d(self, q: np.ndarray) -> list[Any]:
        from .model import Box, Capsule, Segment, Sphere

        ax = self.ax
        arts: list[Any] = []
        shaped = set()
        pose = poses(self.scene, q)
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 13), np.linspace(0, np.pi, 7))
        unit = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
        for i, shape, pts, r in world_points(self.scene, q):
            shaped.add(i)
            color = f"C{i % 10}"
            rot = pose[i][1]
            if isinstance(shape, Sphere) and r > 0:
                s = pts[0] + r * unit @ rot.T
                arts.append(ax.plot_wireframe(s[..., 0], s[..., 1], s[..., 2], color=color,
                                              lw=1.2))
                tip = pts[0] + rot @ np.array([r, 0.0, 0.0])
                arts += ax.plot(*np.column_stack([pts[0], tip]), color="k", lw=1.0)
            elif isinstance(shape, Box):
                for a, b in _box_edges_3d():
                    arts += ax.plot(*np.column_stack([pts[a], pts[b]]), color=color, lw=2.0)
            elif isinstance(shape, (Segment, Capsule)):
                arts += ax.plot(*pts.T, color=color, lw=3.0)
            else:
                arts.append(ax.scatter(*pts.T, color=color, edgecolor="k", s=20,
                                       depthshade=False))
        for i, (x, _) in enumerate(pose):
            if i not in shaped:
                arts.append(ax.scatter([x[0]], [x[1]], [x[2]], color=f"C{i % 10}",
                                       edgecolor="k", s=20, depthshade=False))
        return arts

    # -- output -------------------------------------------------------------------------------

    def rgba(self, frame: int) -> np.ndarray:
        """Frame ``frame`` rendered: an ``(height, width, 4)`` uint8 array (row 0 at the top)."""
        self.draw(frame)
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba()).copy()

    @property
    def animation(self) -> Any:
        """The :class:`matplotlib.animation.FuncAnimation` over the frames."""
        if self._animation is None:
            from matplotlib.animation import FuncAnimation

            self._animation = FuncAnimation(
                self.figure, self.draw, frames=len(self.states), interval=1000.0 / self.fps,
                blit=False, repeat=True)
        return self._animation

    def to_jshtml(self) -> str:
        """An HTML player of every frame (what Jupyter shows)."""
        return str(self.animation.to_jshtml(fps=self.fps))

    def _repr_html_(self) -> str:
        return self.to_jshtml()

    def save(self, path: str | Path) -> Path:
        """Writes a ``.gif`` (Pillow), ``.mp4`` (ffmpeg) or ``.html`` (a JavaScript player)."""
        path = Path(path)
        writer = _writer(path, self.fps)
        if writer is None:
            path.write_text(self.to_jshtml())
        else:
            self.animation.save(str(path), writer=writer, dpi=self.figure.dpi)
        return path


def _writer(path: Path, fps: float) -> Any:
    """The writer for a file's suffix (None: HTML), or an error naming what is missing."""
    from matplotlib import animation

    suffix = path.suffix.lower()
    if suffix == ".gif":
        return animation.PillowWriter(fps=fps)  # type: ignore[arg-type]  # any rate
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise WriterUnavailableError(
                f"writing {path.name} (MP4) needs ffmpeg, which is not installed or not on "
                "PATH (install ffmpeg, e.g. apt-get install ffmpeg or conda install ffmpeg); "
                "a .gif needs only Pillow")
        return animation.FFMpegWriter(fps=fps)  # type: ignore[arg-type]  # ffmpeg takes any rate
    if suffix in (".html", ".htm"):
        return None
    raise InvalidParameterError(
        f"cannot write {path.name!r}: the file type must be .gif, .mp4 or .html")


def animate(
    tr: Trajectory,
    path: str | Path | None = None,
    *,
    fps: float = 25.0,
    every: int | None = None,
    t_range: Sequence[float] | None = None,
    limits: Sequence[Sequence[float]] | None = None,
    title: bool | str = True,
    figsize: tuple[float, float] = (5.0, 4.0),
    dpi: float = 100.0,
) -> Any:
    """See :meth:`coulomb.Trajectory.animate`."""
    require("matplotlib", extra="plot", what="Trajectory.animate")
    scene = _scene_of(tr)
    fps = float(fps)
    if not (math.isfinite(fps) and fps > 0):
        raise InvalidParameterError(f"fps must be > 0, got {fps}")
    if path is not None:
        _writer(Path(path), fps)  # an unknown type or a missing ffmpeg, before any work
    t = np.asarray(tr.t)
    if every is None:
        h = float(tr.h)
        every = max(1, round(1.0 / (fps * h)))  # real time
    if int(every) < 1:
        raise InvalidParameterError(f"every must be >= 1, got {every}")
    if t_range is None:
        t0, t1 = float(t[0]), float(t[-1])
    else:
        t0, t1 = float(t_range[0]), float(t_range[1])
    if not t0 <= t1:
        raise InvalidParameterError(f"t_range must be (t0, t1) with t0 <= t1, got {t_range}")
    rows = np.flatnonzero((t >= t0 - 1e-12) & (t <= t1 + 1e-12))
    if len(rows) == 0:
        raise InvalidParameterError(
            f"no state in t_range {t_range} (the trajectory spans {t[0]:g} to {t[-1]:g} s)")
    states = rows[::int(every)]
    dim = scene.dim
    if limits is None:
        lim = auto_limits(tr, states)
    else:
        lim = np.asarray(limits, dtype=np.float64)
        if lim.shape != (dim, 2) or not np.all(lim[:, 0] < lim[:, 1]):
            raise InvalidParameterError(
                f"limits must be {dim} pairs (low, high) with low < high, got {limits!r}")
    anim = SceneAnimation(tr, states, fps, lim, title, figsize, dpi)
    anim.draw(0)
    if path is not None:
        return anim.save(path)
    return anim
