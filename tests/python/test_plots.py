"""Trajectory.plot and Study.plot: every coordinate labelled by body, name and unit, each
label on the line of its coordinate, axis units present, and the Pareto front's labels kept
apart."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from coulomb import (  # noqa: E402
    Box,
    GapContact,
    HalfSpace,
    Model,
    Particle,
    Point,
    RigidBody2D,
    RigidBody3D,
    Scene,
    Sphere,
)
from coulomb._plot import text_box  # noqa: E402
from coulomb.study import Study, pareto_front  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def legend_texts(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def planar_scene() -> Scene:
    scene = Scene(dim=2)
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    ball = scene.add(Particle(mass=1.0, position=(0.0, 0.5), name="ball"))
    box = scene.add(RigidBody2D(mass=1.0, inertia=0.1, position=(1.0, 0.4), angle=0.3,
                                angular_velocity=2.0, name="box"))
    scene.contact(scene.attach(ball, Point()), floor)
    scene.contact(scene.attach(box, Box((0.2, 0.1))), floor, mu=0.5)
    return scene


def test_q_lines_are_labelled_by_body_coordinate_and_unit():
    tr = planar_scene().simulate(0.3, 1e-3)
    fig = tr.plot()
    q_ax, e_ax, p_ax = fig.axes
    expected = ["ball x [m]", "ball y [m]", "box x [m]", "box y [m]", "box theta [rad]"]
    assert legend_texts(q_ax) == expected
    # each label sits on its own coordinate's line
    for j, line in enumerate(q_ax.get_lines()):
        assert line.get_label() == expected[j]
        np.testing.assert_array_equal(line.get_ydata(), tr.q[:, j])
    assert "m" in q_ax.get_ylabel() and "rad" in q_ax.get_ylabel()
    assert e_ax.get_ylabel() == "energy [J]"
    assert legend_texts(e_ax) == ["kinetic", "potential", "total"]
    np.testing.assert_array_equal(e_ax.get_lines()[2].get_ydata(), tr.total_energy)
    assert p_ax.get_ylabel() == "normal impulse per step [N s]"
    assert p_ax.get_xlabel() == "t [s]"


def test_unnamed_and_spatial_bodies_get_kind_and_index():
    scene = Scene(dim=3)
    floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    p = scene.add(Particle(mass=1.0, position=(0.0, 0.0, 1.0)))
    cube = scene.add(RigidBody3D(mass=1.0, position=(1.0, 0.0, 1.0)))
    scene.contact(scene.attach(p, Sphere(0.1)), floor)
    scene.contact(scene.attach(cube, Box((0.1, 0.1, 0.1))), floor)
    tr = scene.simulate(0.01, 1e-3)
    texts = legend_texts(tr.plot().axes[0])
    assert texts == ["particle 0 x [m]", "particle 0 y [m]", "particle 0 z [m]",
                     "rigid body 1 x [m]", "rigid body 1 y [m]", "rigid body 1 z [m]",
                     "rigid body 1 qw [-]", "rigid body 1 qx [-]", "rigid body 1 qy [-]",
                     "rigid body 1 qz [-]"]


def test_generalized_model_coordinates_are_numbered():
    model = Model(dim=2, mass_matrix=np.eye(2), q0=[1.0, 0.0],
                  contacts=[GapContact(gap=lambda q: q[0], normal_jacobian=lambda q: [1, 0])])
    tr = model.simulate(0.01, 1e-3)
    ax = tr.plot().axes[0]
    assert legend_texts(ax) == ["q[0]", "q[1]"]
    assert ax.get_ylabel() == "q (generalized)"


def crowded_study() -> Study:
    """Ten settings on the Pareto front within 4% of each other, and two slow inaccurate ones
    decades away: on log axes the front's points sit almost on top of each other."""
    records = []
    for i, (h, solver) in enumerate(itertools.product([1e-3, 2e-3, 5e-3, 1e-2, 2e-2],
                                                      ["nsgs", "lemke"])):
        records.append({"h": h, "solver": solver, "time": 1e-3 * (1 + 0.004 * i),
                        "error": 1e-4 * (1 - 0.004 * i)})
    records.append({"h": 0.1, "solver": "nsgs", "time": 10.0, "error": 10.0})
    records.append({"h": 0.1, "solver": "lemke", "time": 1.0, "error": 1.0})
    return Study(records, ["h", "solver"], {"x": 0.0}, name="crowded")


def test_pareto_labels_do_not_overlap_and_the_legend_names_the_settings(tmp_path):
    s = crowded_study()
    front = pareto_front(s.records)
    assert len(front) == 10
    ax = s.plot(path=tmp_path / "p.png")
    renderer = ax.figure.canvas.get_renderer()
    # the points are crowded: labels at one fixed offset would overlap
    px = ax.transData.transform([(r["time"], r["error"]) for r in front])
    assert np.max(np.ptp(px, axis=0)) < 8
    labels = [t for t in ax.texts if t.get_text().isdigit()]
    assert sorted(int(t.get_text()) for t in labels) == list(range(1, 11))
    boxes = [text_box(t, renderer) for t in labels]  # the text, not its leader line
    inside = ax.get_window_extent(renderer)
    assert sum(inside.contains(b.x0, b.y0) and inside.contains(b.x1, b.y1) for b in boxes) >= 8
    for a, b in itertools.combinations(boxes, 2):
        assert not a.overlaps(b)
    texts = legend_texts(ax)
    assert texts[:2] == ["settings", "Pareto front"]
    assert texts[2:] == [f"{i + 1}: h={r['h']}, solver={r['solver']}"
                         for i, r in enumerate(front)]
    # each number is beside its own point
    for t, box in zip(labels, boxes, strict=True):
        r = front[int(t.get_text()) - 1]
        assert t.xy == (r["time"], r["error"])
        # the text is drawn near its point (within 70 pixels)
        x, y = ax.transData.transform(t.xy)
        assert np.hypot(box.x0 + box.x1 - 2 * x, box.y0 + box.y1 - 2 * y) < 140
    assert ax.get_xlabel() == "wall time [s]"
    assert "[-]" in ax.get_ylabel() and "relative" in ax.get_ylabel()
