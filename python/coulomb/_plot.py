"""Labels with units for the plots of trajectories and studies, and text placement that keeps
annotations apart."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .model import Scene

__all__ = ["body_names", "coordinate_labels", "place_labels", "study_axis_label", "text_box"]

#: the coordinates of each body kind, with units, per scene dimension.
_COORDS: dict[tuple[str, int], tuple[tuple[str, str], ...]] = {
    ("particle", 2): (("x", "m"), ("y", "m")),
    ("particle", 3): (("x", "m"), ("y", "m"), ("z", "m")),
    ("planar", 2): (("x", "m"), ("y", "m"), ("theta", "rad")),
    ("spatial", 3): (("x", "m"), ("y", "m"), ("z", "m"), ("qw", "-"), ("qx", "-"), ("qy", "-"),
                     ("qz", "-")),
}


def body_names(scene: Scene) -> list[str]:
    """Each body's ``name``, or its kind and index (``"particle 0"``, ``"rigid body 1"``)."""
    kinds = {"particle": "particle", "planar": "rigid body", "spatial": "rigid body"}
    return [b.name or f"{kinds.get(b.kind, 'body')} {i}" for i, b in enumerate(scene.bodies)]


def coordinate_labels(scene: Scene | None, nq: int) -> list[str]:
    """One label per column of ``q``: body name, coordinate and unit (``"ball y [m]"``,
    ``"box theta [rad]"``); ``"q[i]"`` for a generalized-coordinate model, whose units the
    model does not say."""
    if scene is None:
        return [f"q[{i}]" for i in range(nq)]
    labels: list[str] = []
    for name, body in zip(body_names(scene), scene.bodies, strict=True):
        for coord, unit in _COORDS[(body.kind, scene.dim)]:
            labels.append(f"{name} {coord} [{unit}]")
    return labels


def study_axis_label(column: str) -> str:
    """An axis label with its unit for a study column."""
    if column == "time":
        return "wall time [s]"
    if column == "error":
        return "error (worst relative, against the reference) [-]"
    if column.startswith("rel_error_"):
        return f"relative error of {column[len('rel_error_'):]} [-]"
    if column.startswith("error_"):
        return f"|{column[len('error_'):]} - reference| (units of {column[len('error_'):]})"
    return column


def _ring_offsets() -> list[tuple[float, float]]:
    """Label offsets (points) around a marker: beside it first, then rings further out."""
    out = [(4.0, 4.0), (4.0, -12.0), (-14.0, 4.0), (-14.0, -12.0)]
    for radius in (18.0, 30.0, 42.0, 56.0):
        for k in range(12):
            a = 2 * math.pi * k / 12 + math.pi / 12
            out.append((radius * math.cos(a) - 4.0, radius * math.sin(a) - 4.0))
    return out


def text_box(ann: Any, renderer: Any) -> Any:
    """The display box of an annotation's text alone (without its leader line), where it is
    drawn."""
    from matplotlib.text import Text

    ann.update_positions(renderer)
    return Text.get_window_extent(ann, renderer)


def place_labels(ax: Any, points: list[tuple[float, float]], texts: list[str],
                 fontsize: float = 7.0) -> list[Any]:
    """Annotates ``points`` (data coordinates) with ``texts``, each label at the first of a
    ring of offsets where it lies inside the axes and overlaps no label placed before it (else
    the first where it overlaps none; else beside its marker); a label away from its marker
    gets a thin leader line. Returns the annotations."""
    fig = ax.figure
    ax.get_xlim(), ax.get_ylim()  # settles the autoscaled limits the offsets are measured in
    get = getattr(fig.canvas, "get_renderer", None)  # Agg canvases; others: the figure's
    renderer = get() if get is not None else fig._get_renderer()
    inside = ax.get_window_extent(renderer)
    placed: list[Any] = []
    boxes: list[Any] = []
    for (x, y), text in zip(points, texts, strict=True):
        ann = ax.annotate(text, (x, y), xytext=(4, 4), textcoords="offset points",
                          fontsize=fontsize)
        choice = None
        for dx, dy in _ring_offsets():
            ann.set_position((dx, dy))
            box = text_box(ann, renderer)
            if any(box.expanded(1.05, 1.1).overlaps(b) for b in boxes):
                continue
            if (inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0
                    and box.y1 <= inside.y1):
                choice = (dx, dy)
                break
            if choice is None:
                choice = (dx, dy)  # apart but outside the axes: kept unless better turns up
        dx, dy = choice if choice is not None else (4.0, 4.0)
        ann.set_position((dx, dy))
        if math.hypot(dx + 4.0, dy + 4.0) > 15.0:  # away from its marker: a leader line
            ann.remove()
            ann = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                              fontsize=fontsize,
                              arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "0.4",
                                          "shrinkA": 0, "shrinkB": 2})
        boxes.append(text_box(ann, renderer))
        placed.append(ann)
    return placed
