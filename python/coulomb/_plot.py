"""Labels with units for the plots of trajectories and studies, and text placement that keeps
annotations apart."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .model import Scene

__all__ = ["body_names", "coordinate_labels", "place_labels", "study_axis_label"]

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


def place_labels(ax: Any, points: list[tuple[float, float]], texts: list[str],
                 fontsize: float = 7.0) -> list[Any]:
    """Annotates ``points`` (data coordinates) with ``texts``, each label moved to the first
    of a ring of offsets where it overlaps no label placed before it (and no other point's
    marker, approximately). Returns the annotations."""
    fig = ax.figure
    ax.get_xlim(), ax.get_ylim()  # settles the autoscaled limits the offsets are measured in
    renderer = fig.canvas.get_renderer()
    offsets = [(4, 4), (4, -12), (-14, 4), (-14, -12), (4, 14), (-14, 14), (4, -22),
               (-14, -22), (14, 0), (-24, 0), (4, 24), (4, -32)]
    placed: list[Any] = []
    boxes: list[Any] = []
    for (x, y), text in zip(points, texts, strict=True):
        ann = None
        for dx, dy in offsets:
            if ann is not None:
                ann.remove()
            ann = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                              fontsize=fontsize)
            box = ann.get_window_extent(renderer).expanded(1.05, 1.1)
            if not any(box.overlaps(b) for b in boxes):
                break
        assert ann is not None
        boxes.append(ann.get_window_extent(renderer))
        placed.append(ann)
    return placed
