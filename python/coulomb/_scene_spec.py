"""A :class:`~coulomb.model.Scene` lowered to the form the core reads: plain lists and dicts,
every body, shape, half-space, pair and joint by index (``_core.step_simulate``'s scene)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._arguments import _vector
from ._solids import _check_solid
from .errors import InvalidParameterError

if TYPE_CHECKING:
    from ._solids import Shape
    from .model import Scene


def solid_of(scene: Scene, shape: Shape) -> dict[str, Any] | None:
    """a shape's solid form, checked, or None (no volume, or a degenerate hull of a
    point shape's points)."""
    form = shape._solid(scene.dim)
    if form is None:
        return None
    if shape._point_form:
        try:
            _check_solid(form, scene.dim)
        except InvalidParameterError:
            return None
    return form


def scene_spec(scene: Scene) -> dict[str, Any]:
    """The scene as the core reads it (``_core.step_simulate``'s first argument): plain lists
    and dicts, every shape, pair and joint by index."""
    bodies = []
    for b in scene.bodies:
        spec = b._spec(scene.dim)
        f = b.force if b.force is not None else [0.0] * scene.dim
        spec["force"] = _vector("force", f, scene.dim)
        bodies.append(spec)
    body_index = {id(b): i for i, b in enumerate(scene.bodies)}
    shapes: list[dict[str, Any]] = []
    shape_index: dict[int, int] = {}
    for body, shape in scene.shapes:
        if shape._point_form:
            pts, r = shape._points(scene.dim)
            shape_index[id(shape)] = len(shapes)
            shapes.append({"body": body_index[id(body)], "points": pts, "radius": r})
    auto = any(p[0] == "solids" for p in scene.pairs)
    wanted = {id(x) for k, a, b, _, _ in scene.pairs if k in ("solid", "solid_half_space")
              for x in (a, b)}
    solids: list[dict[str, Any]] = []
    solid_index: dict[int, int] = {}
    for body, shape in scene.shapes:
        form = solid_of(scene, shape) if (auto or id(shape) in wanted) else None
        if form is not None:
            form["body"] = body_index[id(body)]
            solid_index[id(shape)] = len(solids)
            solids.append(form)
    for st in scene.statics:
        form = st._solid(scene.dim)
        form["body"] = None
        solid_index[id(st)] = len(solids)
        solids.append(form)
    hs_index = {id(h): i for i, h in enumerate(scene.half_spaces)}
    pairs = []
    for k, a, b, mu, e in scene.pairs:
        if k in ("spheres", "solids"):
            ia = ib = 0
        elif k == "half_space":
            ia, ib = shape_index[id(a)], hs_index[id(b)]
        elif k == "solid_half_space":
            ia, ib = solid_index[id(a)], hs_index[id(b)]
        elif k == "sphere" and not (auto and id(a) in solid_index
                                    and id(b) in solid_index):
            ia, ib = shape_index[id(a)], shape_index[id(b)]
        else:
            # a declared sphere pair under contact_all is a solid pair, so the broad
            # phase leaves it to the declaration
            k, ia, ib = "solid", solid_index[id(a)], solid_index[id(b)]
        pairs.append({"kind": k, "a": ia, "b": ib, "mu": mu, "e": e})
    pairs += _all_half_space_pairs(scene, shape_index, solid_index, hs_index)
    return {
        "dim": scene.dim,
        "gravity": scene.gravity,
        "bodies": bodies,
        "shapes": shapes,
        "half_spaces": [
            {"point": _vector("point", h.point, scene.dim),
             "normal": _vector("normal", h.normal, scene.dim)}
            for h in scene.half_spaces
        ],
        "pairs": pairs,
        "solids": solids,
        "joints": [j._spec(scene.dim, scene._body_index) for j in scene.joints],
    }

def _all_half_space_pairs(scene: Scene, shape_index: dict[int, int], solid_index: dict[int, int],
                          hs_index: dict[int, int]) -> list[dict[str, Any]]:
    """Under :meth:`Scene.contact_all`, every attached shape against every half-space not
    declared by :meth:`Scene.contact`, in the order of the shapes, then of the half-spaces (the
    order the same pairs declared by hand would have), with contact_all's mu and e."""
    auto = [p for p in scene.pairs if p[0] == "solids"]
    if not auto:
        return []
    _, _, _, mu, e = auto[0]
    declared = {(id(a), id(b)) for k, a, b, _, _ in scene.pairs
                if k in ("half_space", "solid_half_space")}
    out = []
    for _, shape in scene.shapes:
        for h in scene.half_spaces:
            if (id(shape), id(h)) in declared:
                continue
            if shape._point_form:
                kind, ia = "half_space", shape_index[id(shape)]
            else:
                kind, ia = "solid_half_space", solid_index[id(shape)]
            out.append({"kind": kind, "a": ia, "b": hs_index[id(h)], "mu": mu, "e": e})
    return out
