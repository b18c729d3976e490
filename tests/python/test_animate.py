"""Trajectory.animate: frames rendered to pixels (Agg) and checked against where the
trajectory's physics puts each body: a ball falls onto the floor, a box turns at a known rate,
a ramp's solid side is shaded, and a GIF holds the frames asked for."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from coulomb import (  # noqa: E402
    Box,
    GapContact,
    HalfSpace,
    Model,
    Particle,
    Point,
    Polygon,
    RigidBody2D,
    RigidBody3D,
    Scene,
    Segment,
    Sphere,
)
from coulomb._animate import (  # noqa: E402
    HALF_SPACE_FILL,
    WriterUnavailableError,
    _box_edges_3d,
)
from coulomb._extras import MissingExtraError  # noqa: E402
from coulomb.errors import InvalidParameterError  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402

SMALL = {"figsize": (3.0, 3.0), "dpi": 60}


def falling_ball(dim: int = 2, radius: float = 0.1) -> Scene:
    """A ball dropped from 1 m onto the floor, no rebound (lands at t = sqrt(2 * 0.9 / g))."""
    scene = Scene(dim=dim)
    up = np.eye(dim)[dim - 1]
    ball = scene.add(Particle(mass=1.0, position=tuple(up * 1.0), name="ball"))
    floor = scene.add(HalfSpace(tuple(0 * up), tuple(up)))
    scene.contact(scene.attach(ball, Sphere(radius)), floor, e=0.0)
    return scene


def mask_of(img: np.ndarray, color: object, tol: float = 0.08) -> np.ndarray:
    """Pixels within ``tol`` (per channel, 0..1) of a colour."""
    rgb = img[..., :3].astype(float) / 255.0
    return np.all(np.abs(rgb - np.array(to_rgb(color))) < tol, axis=-1)


def bluish(img: np.ndarray) -> np.ndarray:
    """Pixels with C0's hue (blue well above red), whatever they are blended over: the
    antialiased thin lines of a 3D wireframe over white or over the grey floor."""
    rgb = img[..., :3].astype(float) / 255.0
    return rgb[..., 2] - rgb[..., 0] > 0.2


def pixel(anim, xy) -> tuple[int, int]:
    """(row, column) in the rendered buffer of a data point (row 0 at the top)."""
    x, y = anim.ax.transData.transform(xy)
    height = anim.figure.canvas.get_width_height()[1]
    return round(float(height - y)), round(float(x))


def colour_at(img: np.ndarray, rc: tuple[int, int]) -> np.ndarray:
    return img[rc[0], rc[1], :3].astype(float) / 255.0


def test_falling_ball_is_lower_in_later_frames_where_the_trajectory_puts_it():
    tr = falling_ball().simulate(0.75, 1e-3)
    anim = tr.animate(every=250, **SMALL)  # t = 0, 0.25, 0.5, 0.75
    assert [round(float(tr.t[k]), 9) for k in anim.states] == [0.0, 0.25, 0.5, 0.75]
    rows = []
    for frame in range(len(anim)):
        img = anim.rgba(frame)
        disk = mask_of(img, "C0")
        assert disk.sum() > 20
        r, c = np.argwhere(disk).mean(axis=0)
        # the disk's centre is where the trajectory's position maps to on screen
        y = float(tr.q[anim.states[frame], 1])
        er, ec = pixel(anim, (0.0, y))
        assert abs(r - er) < 2.0 and abs(c - ec) < 2.0
        # free fall until it lands at y = r = 0.1 (the analytic drop)
        t = float(tr.t[anim.states[frame]])
        assert y == pytest.approx(max(1.0 - 0.5 * 9.81 * t * t, 0.1), abs=0.01)
        # its area is the disk's: pi r^2 in pixels (the black rim and radius line excluded)
        r_px = abs(pixel(anim, (0.0, 0.1))[0] - pixel(anim, (0.0, 0.0))[0])
        assert 0.5 * math.pi * r_px**2 < disk.sum() < 1.1 * math.pi * r_px**2
        rows.append(r)
    assert rows[0] < rows[1] < rows[2]  # falling: lower on screen (rows grow downwards)
    assert abs(rows[3] - rows[2]) < 2.0  # landed at 0.43 s: at rest on the floor since


def turning_box(omega: float) -> Scene:
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    box = scene.add(RigidBody2D(mass=1.0, inertia=1.0, position=(0.0, 0.0), angle=0.0,
                                angular_velocity=omega, name="box"))
    scene.attach(box, Box((0.5, 0.2)))
    return scene


def test_turning_box_corners_move_as_its_rotation_says():
    omega = math.pi / 2  # a quarter turn per second, counter-clockwise
    tr = turning_box(omega).simulate(1.0, 1e-2)
    anim = tr.animate(every=25, limits=((-1, 1), (-1, 1)), title=False, **SMALL)
    corners = np.array([[0.5, 0.2], [-0.5, 0.2], [-0.5, -0.2], [0.5, -0.2]])
    for frame in range(len(anim)):
        img = anim.rgba(frame)
        th = omega * float(tr.t[anim.states[frame]])
        rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        for corner in corners @ rot.T:
            inside = colour_at(img, pixel(anim, 0.8 * corner))
            outside = colour_at(img, pixel(anim, 1.25 * corner))
            assert np.allclose(inside, to_rgb("C0"), atol=0.05), (frame, th, corner)
            assert np.allclose(outside, (1.0, 1.0, 1.0), atol=0.05), (frame, th, corner)
    # a quarter turn: the long side now vertical
    img = anim.rgba(len(anim) - 1)
    assert float(tr.t[anim.states[-1]]) == pytest.approx(1.0)
    assert np.allclose(colour_at(img, pixel(anim, (0.0, 0.4))), to_rgb("C0"), atol=0.05)
    assert np.allclose(colour_at(img, pixel(anim, (0.4, 0.0))), (1.0, 1.0, 1.0), atol=0.05)
    img0 = anim.rgba(0)
    assert np.allclose(colour_at(img0, pixel(anim, (0.4, 0.0))), to_rgb("C0"), atol=0.05)
    assert np.allclose(colour_at(img0, pixel(anim, (0.0, 0.4))), (1.0, 1.0, 1.0), atol=0.05)


@pytest.mark.parametrize("angle", [0.0, 20.0, -35.0])
def test_half_space_is_shaded_on_its_solid_side(angle):
    scene = Scene(dim=2)
    block = scene.add(Particle(mass=1.0, position=(0.0, 0.3)))
    ramp = scene.add(HalfSpace.ramp(angle))
    scene.contact(scene.attach(block, Point()), ramp, mu=0.5)
    tr = scene.simulate(0.01, 1e-3)
    anim = tr.animate(limits=((-1, 1), (-1, 1)), title=False, **SMALL)
    img = anim.rgba(0)
    n = np.array(ramp.normal)
    checked = {"solid": 0, "free": 0}
    for x in np.linspace(-0.9, 0.9, 7):
        for y in np.linspace(-0.9, 0.9, 7):
            d = float(n @ (x, y))
            if abs(d) < 0.1 or math.hypot(x, y - 0.3) < 0.15:
                continue  # near the boundary line or the block
            rgb = colour_at(img, pixel(anim, (x, y)))
            expected = HALF_SPACE_FILL if d < 0 else (1.0, 1.0, 1.0)
            assert np.allclose(rgb, expected, atol=0.03), (angle, x, y, d, rgb)
            checked["solid" if d < 0 else "free"] += 1
    assert checked["solid"] > 5 and checked["free"] > 5


def test_gif_has_the_frames_and_size_asked_for(tmp_path):
    from PIL import Image

    tr = falling_ball().simulate(0.5, 1e-3)
    path = tr.animate(tmp_path / "ball.gif", every=100, fps=10, **SMALL)
    assert path == tmp_path / "ball.gif"
    with Image.open(path) as gif:
        assert gif.n_frames == 6  # t = 0, 0.1, ..., 0.5
        assert gif.size == (180, 180)  # 3 x 3 inches at 60 dpi
        assert gif.info["duration"] == pytest.approx(100, abs=10)  # 10 frames per second
        first = np.asarray(gif.convert("RGB")).copy()
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB")).copy()
    # the ball (C0) is lower in the last frame than in the first
    r0 = np.argwhere(mask_of(first, "C0", 0.12))[:, 0].mean()
    r1 = np.argwhere(mask_of(last, "C0", 0.12))[:, 0].mean()
    assert r1 > r0 + 20


def test_real_time_by_default_and_t_range():
    tr = falling_ball().simulate(1.0, 1e-3)
    anim = tr.animate(fps=20, **SMALL)
    assert np.allclose(np.diff(tr.t[anim.states]), 0.05)  # one frame per 1/20 s
    part = tr.animate(fps=20, t_range=(0.25, 0.5), **SMALL)
    times = tr.t[part.states]
    assert times[0] == pytest.approx(0.25) and times[-1] == pytest.approx(0.5)
    assert len(part) == 6


def test_title_shows_the_time():
    tr = falling_ball().simulate(0.1, 1e-2)
    anim = tr.animate(every=5, **SMALL)
    anim.draw(1)
    assert anim.ax.get_title() == "t = 0.050 s"
    anim = tr.animate(every=5, title="{t:.2f} s after release", **SMALL)
    anim.draw(2)
    assert anim.ax.get_title() == "0.10 s after release"


def test_jupyter_shows_an_html_player_with_every_frame():
    tr = falling_ball().simulate(0.2, 1e-2)
    anim = tr.animate(every=5, figsize=(2, 2), dpi=30)
    html = anim._repr_html_()
    assert len(anim) == 5 and html.count("frames[") >= 5 and "<script" in html


def test_3d_falling_sphere_and_floor_patch():
    tr = falling_ball(dim=3, radius=0.15).simulate(0.6, 1e-3)
    anim = tr.animate(every=300, **SMALL)  # t = 0, 0.3, 0.6
    rows = []
    for frame in range(len(anim)):
        img = anim.rgba(frame)
        wire = bluish(img)
        assert wire.sum() > 10
        rows.append(np.argwhere(wire)[:, 0].mean())
        # the floor patch is shaded: grey pixels of the half-space's fill blended on white
        assert mask_of(img, tuple(0.5 * np.array(HALF_SPACE_FILL) + 0.5), 0.05).sum() > 200
    assert rows[0] < rows[1] < rows[2]


def test_3d_box_edges_follow_the_quaternion():
    omega = 1.2
    scene = Scene(dim=3, gravity=(0.0, 0.0, 0.0))
    box = scene.add(RigidBody3D(mass=1.0, position=(0.1, -0.2, 0.3),
                                angular_velocity=(0.0, 0.0, omega)))
    half = np.array([0.4, 0.2, 0.1])
    scene.attach(box, Box(tuple(half)))
    tr = scene.simulate(0.5, 1e-3)
    anim = tr.animate(every=250, **SMALL)
    for frame in range(len(anim)):
        lines = anim.draw(frame)
        assert len(lines) == 12
        # the drawn edges are the box's edges turned by the body's quaternion
        k = anim.states[frame]
        w, x, y, z = tr.q[k, 3:7] / np.linalg.norm(tr.q[k, 3:7])
        th = 2 * math.atan2(z, w)
        assert abs(x) + abs(y) < 1e-9  # a turn about z only
        assert th == pytest.approx(omega * tr.t[k], rel=1e-3, abs=1e-9)
        rot = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0],
                        [0, 0, 1]])
        signs = np.array(np.meshgrid(*[[-1.0, 1.0]] * 3, indexing="ij")).reshape(3, -1).T
        corners = tr.q[k, :3] + (signs * half) @ rot.T
        drawn = sorted(tuple(np.round(np.array(ln.get_data_3d()).T.ravel(), 9)) for ln in lines)
        expected = sorted(tuple(np.round(np.concatenate([corners[a], corners[b]]), 9))
                          for a, b in _box_edges_3d())
        assert np.allclose(drawn, expected, atol=1e-9)


SHAPES_2D = [Point(), Point((0.1, -0.1)), Sphere(0.2), Sphere(0.0), Box((0.3, 0.2)),
             Segment((-0.3, 0.0), (0.3, 0.1), radius=0.05), Segment((-0.3, 0.0), (0.3, 0.1)),
             Polygon([(0.0, 0.0), (0.4, 0.0), (0.0, 0.3)]), Polygon([(0.0, 0.0), (0.3, 0.1)]),
             Polygon([(0.1, 0.1)]), None]
SHAPES_3D = [Point(), Sphere(0.2), Sphere(0.0), Box((0.3, 0.2, 0.1)),
             Segment((-0.3, 0.0, 0.0), (0.3, 0.1, 0.2)),
             Polygon([(0.0, 0.0, 0.0), (0.4, 0.0, 0.0), (0.0, 0.3, 0.1)]), None]


def screen(anim, xyz) -> tuple[float, float]:
    """(row, column) of a 3D data point on the rendered frame."""
    from mpl_toolkits.mplot3d import proj3d

    x, y, _ = proj3d.proj_transform(*xyz, anim.ax.get_proj())
    px, py = anim.ax.transData.transform((x, y))
    return anim.figure.canvas.get_width_height()[1] - py, px


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("kind", ["particle", "rigid"])
def test_every_shape_kind_is_drawn_where_its_points_are(dim, kind):
    """Each shape (or a body without one) shows pixels of its body's colour at every one of
    its world-frame points (2D) or over their projection (3D)."""
    from coulomb._animate import world_points

    for shape in SHAPES_2D if dim == 2 else SHAPES_3D:
        scene = Scene(dim=dim, gravity=(0.0,) * dim)
        pos = (0.2, 0.1) if dim == 2 else (0.2, 0.1, 0.05)
        if kind == "particle":
            body = scene.add(Particle(mass=1.0, position=pos))
        elif dim == 2:
            body = scene.add(RigidBody2D(mass=1.0, position=pos, angle=0.5))
        else:
            body = scene.add(RigidBody3D(mass=1.0, position=pos,
                                         orientation=(0.9, 0.3, -0.2, 0.1)))
        if shape is not None:
            scene.attach(body, shape)
        tr = scene.simulate(1e-3, 1e-3)
        lim = ((-1.0, 1.0),) * dim
        anim = tr.animate(limits=lim, title=False, figsize=(3, 3), dpi=80)
        img = anim.rgba(0)
        mask = bluish(img)
        placed = world_points(scene, tr.q[0])
        pts = placed[0][2] if placed else np.array([pos])
        radius = placed[0][3] if placed else 0.0
        if dim == 2:
            for p in pts:
                r, c = pixel(anim, p)
                assert mask[r - 3:r + 4, c - 3:c + 4].any(), (shape, p)
            if radius > 0:  # filled out to the radius
                r, c = pixel(anim, pts[0] + (0.0, 0.5 * radius))
                assert mask[r, c], (shape, radius)
        else:
            corners = [screen(anim, p + d) for p in pts
                       for d in itertools.product((-radius, radius), repeat=3)]
            (r0, c0), (r1, c1) = np.min(corners, axis=0), np.max(corners, axis=0)
            window = mask[int(r0) - 4:int(r1) + 5, int(c0) - 4:int(c1) + 5]
            assert window.sum() >= 4, shape
            assert window.sum() >= 0.5 * mask.sum(), shape  # drawn there, not elsewhere


def polygon_area_3d(poly: np.ndarray) -> float:
    return 0.5 * float(np.linalg.norm(sum(np.cross(poly[i], poly[(i + 1) % len(poly)])
                                          for i in range(len(poly)))))


@pytest.mark.parametrize("angle", [0.0, 20.0, 50.0])
def test_3d_half_space_patch_is_the_plane_inside_the_axes_box(angle):
    from coulomb._animate import _plane_patch

    lim = np.array([[-1.0, 1.0], [-1.0, 1.0], [-1.0, 1.0]])
    hs = HalfSpace.ramp(angle, dim=3)
    n = np.array(hs.normal)
    patch = _plane_patch(np.array(hs.point), n, lim)
    assert np.allclose(patch @ n, 0.0, atol=1e-12)  # on the plane
    assert np.all(patch >= lim[:, 0] - 1e-12) and np.all(patch <= lim[:, 1] + 1e-12)
    th = math.radians(angle)
    # z = -tan(th) x: leaves through the x faces while tan(th) <= 1, else the z faces
    width = 2.0 / math.cos(th) if math.tan(th) <= 1 else 2.0 / math.sin(th)
    assert polygon_area_3d(patch) == pytest.approx(width * 2.0, rel=1e-12)
    # a plane that misses the box has no patch
    assert len(_plane_patch(np.array([0.0, 0.0, -3.0]), n, lim)) < 3


def test_generalized_model_has_nothing_to_draw():
    model = Model(dim=2, mass_matrix=np.eye(1), q0=[1.0],
                  contacts=[GapContact(gap=lambda q: q[0], normal_jacobian=lambda q: [1.0])])
    tr = model.simulate(0.01, 1e-3)
    with pytest.raises(TypeError, match=r"Trajectory.plot"):
        tr.animate()


def test_bad_options_and_missing_writers_are_refused_before_any_work(tmp_path, monkeypatch):
    tr = falling_ball().simulate(0.05, 1e-2)
    with pytest.raises(InvalidParameterError, match=r"\.gif, \.mp4 or \.html"):
        tr.animate(tmp_path / "ball.avi")
    with pytest.raises(InvalidParameterError, match="limits"):
        tr.animate(limits=((0, 1),))
    with pytest.raises(InvalidParameterError, match="t_range"):
        tr.animate(t_range=(5.0, 6.0))
    with pytest.raises(InvalidParameterError, match="every"):
        tr.animate(every=0)
    from matplotlib import animation

    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    with pytest.raises(WriterUnavailableError, match="needs ffmpeg"):
        tr.animate(tmp_path / "ball.mp4")
    assert not (tmp_path / "ball.mp4").exists()


def test_without_matplotlib_names_the_plot_extra(monkeypatch):
    import sys

    tr = falling_ball().simulate(0.05, 1e-2)
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(MissingExtraError, match=r"coulomb\[plot\]"):
        tr.animate()
