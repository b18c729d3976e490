"""Building a scene: identity lookups that stay right when the lists change, the checks of
bad handles, and the fast paths of the argument checks giving what the general path gives."""

from __future__ import annotations

import math

import coulomb
import numpy as np
import pytest
from coulomb import HalfSpace, Revolute, RigidBody3D, Scene, Sphere
from coulomb._arguments import _vector
from coulomb.errors import CoulombError, InvalidParameterError
from hypothesis import given
from hypothesis import strategies as st


def _balls(count: int) -> tuple[Scene, list, list, HalfSpace]:
    scene = Scene(dim=3)
    floor = scene.add(HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    bodies, shapes = [], []
    for k in range(count):
        b = scene.add(RigidBody3D(mass=1.0, inertia=(0.1, 0.1, 0.1),
                                  position=(3.0 * k, 0.0, 1.0 + k)))
        bodies.append(b)
        shapes.append(scene.attach(b, Sphere(0.5)))
    return scene, bodies, shapes, floor


def test_handles_not_in_the_scene_are_refused_by_name():
    scene, bodies, shapes, floor = _balls(3)
    stray_body = RigidBody3D(mass=1.0)
    with pytest.raises(InvalidParameterError, match="this body was not added"):
        scene.attach(stray_body, Sphere(1.0))
    with pytest.raises(InvalidParameterError, match="already attached"):
        scene.attach(bodies[1], shapes[1])
    with pytest.raises(InvalidParameterError, match="this shape was not added"):
        scene.contact(Sphere(1.0), floor)
    with pytest.raises(InvalidParameterError, match="this shape was not added"):
        scene.contact(shapes[0], Sphere(1.0))
    with pytest.raises(InvalidParameterError, match="this half-space was not added"):
        scene.contact(shapes[0], HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    with pytest.raises(InvalidParameterError, match="same body"):
        scene.contact(shapes[2], scene.attach(bodies[2], Sphere(0.2)))
    with pytest.raises(InvalidParameterError, match="joint's body was not added"):
        scene.add(Revolute(bodies[0], stray_body, anchor=(0.0, 0.0, 1.0), axis=(0.0, 1.0, 0.0)))
    mesh = coulomb.TriangleMesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    scene.add(mesh)
    with pytest.raises(InvalidParameterError, match="already added"):
        scene.add(mesh)


def test_lookups_follow_lists_changed_behind_the_scene():
    """The lists are public: an entry removed or replaced directly must not be found where it
    was, and the others must be found where they now are (the spec's indices say so)."""
    scene, _bodies, shapes, floor = _balls(5)
    scene.contact(shapes[3], floor, mu=0.3)
    removed_body, removed_shape = scene.shapes.pop(0)
    scene.bodies.remove(removed_body)
    with pytest.raises(InvalidParameterError, match="this shape was not added"):
        scene.contact(removed_shape, floor)
    with pytest.raises(InvalidParameterError, match="this body was not added"):
        scene.attach(removed_body, Sphere(0.1))
    scene.contact(shapes[1], floor, mu=0.1)
    scene.contact(shapes[1], shapes[2], mu=0.2)
    spec = scene._spec()
    # shapes[3] is now the third shape, on the third body; shapes[1] the first
    assert [s["body"] for s in spec["shapes"]] == [0, 1, 2, 3]
    assert [(p["kind"], p["a"], p["b"], p["mu"]) for p in spec["pairs"]] == [
        ("half_space", 2, 0, 0.3), ("half_space", 0, 0, 0.1), ("sphere", 0, 1, 0.2)]
    # a replaced entry (of a shape in no pair): the new object is found at its place, the
    # old one nowhere
    other = Sphere(0.5)
    scene.shapes[3] = (scene.shapes[3][0], other)
    scene.contact(other, floor)
    with pytest.raises(InvalidParameterError, match="this shape was not added"):
        scene.contact(shapes[4], floor)
    assert scene._spec()["pairs"][-1]["a"] == 3


def test_a_scene_of_many_balls_names_each_pair_by_its_own_indices():
    """Declared pairs of a larger scene, in declaration order, carry the indices of the
    shapes and bodies they were declared with (checked against the objects themselves)."""
    scene, _bodies, shapes, floor = _balls(300)
    rng = np.random.default_rng(3)
    picks = rng.permutation(300)[:150]
    for k in picks:
        scene.contact(shapes[k], floor, mu=float(k))
    spec = scene._spec()
    assert [p["a"] for p in spec["pairs"]] == list(picks)
    assert [p["mu"] for p in spec["pairs"]] == [float(k) for k in picks]
    assert [s["body"] for s in spec["shapes"]] == list(range(300))


_entry = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(1 << 60), max_value=1 << 60),
    st.sampled_from([2**53, -(2**53), 2**53 + 1, 0, -0.0, True, False, 10**400]),
    st.builds(np.float64, st.floats(allow_nan=False)),
)


def _outcome(value, n):
    try:
        return ("ok", _vector("v", value, n))
    except (CoulombError, OverflowError, ValueError, TypeError) as exc:
        return (type(exc).__name__, str(exc))


@given(st.lists(_entry, min_size=1, max_size=5), st.sampled_from([tuple, list]))
def test_a_short_vector_of_python_numbers_is_read_as_numpy_reads_it(entries, kind):
    value = kind(entries)
    n = len(entries)
    got = _outcome(value, n)
    as_array = _outcome(np.asarray(entries, dtype=object)
                        if any(isinstance(x, int) and abs(x) > 2**62 for x in entries)
                        else np.asarray(entries), n)
    if got[0] == "ok":
        assert as_array[0] == "ok"
        assert all(type(x) is float for x in got[1])
        # bitwise, -0.0 included
        assert [math.copysign(1.0, x) for x in got[1]] == [
            math.copysign(1.0, x) for x in as_array[1]]
        assert got[1] == as_array[1]
    else:
        assert got[0] == as_array[0]
    # a wrong length is refused whatever the entries
    assert _outcome(value, n + 1)[0] != "ok"


# the units' span (kg m^2 over 10^-8..10^8 in mass and length); at 1e-300 beside 1e169
# LAPACK's eigenvalues of the diagonal matrix underflow to 0, and the general check refuses
# moments that are positive (the principal-moments path accepts them: they are)
_moment = st.floats(min_value=1e-40, max_value=1e40)
_axis = st.tuples(st.integers(0, 3), st.sampled_from([1.0, -1.0]), st.booleans())


@given(st.tuples(_moment, _moment, _moment), _axis)
def test_a_body_with_principal_moments_has_the_general_checks_spec(moments, axis):
    k, sign, negative_zeros = axis
    zero = -0.0 if negative_zeros else 0.0
    quat = tuple(sign if i == k else zero for i in range(4))
    fast = RigidBody3D(mass=2.0, inertia=moments, orientation=quat,
                       position=(1.0, -2.0, 3.5), velocity=(0.5, 0, -1))._spec(3)
    general = RigidBody3D(mass=2.0, inertia=np.array(moments), orientation=np.array(quat),
                          position=(1.0, -2.0, 3.5), velocity=(0.5, 0, -1))._spec(3)
    assert fast == general
    assert [math.copysign(1.0, x) for x in fast["q0"]] == [
        math.copysign(1.0, x) for x in general["q0"]]


@pytest.mark.parametrize("inertia, message", [
    ((1.0, 0.0, 1.0), "positive definite"),
    ((1.0, -1.0, 1.0), "positive definite"),
    ((1.0, float("nan"), 1.0), "non-finite"),
    ((1.0, 1.0), "3 moments or 3x3"),
])
def test_bad_principal_moments_get_the_general_messages(inertia, message):
    with pytest.raises(CoulombError, match=message):
        RigidBody3D(mass=1.0, inertia=inertia)._spec(3)
