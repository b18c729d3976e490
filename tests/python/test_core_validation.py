"""The stepper's string and bounded options (drift, drift_bias, restitution) are checked once,
by the core, with coulomb.errors' classes: a wrong type is an ArgumentTypeError (an
InvalidParameterError and a TypeError), a wrong value an InvalidParameterError, each naming
the keyword; Scene.simulate and Model.simulate refuse the same inputs the same way."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import coulomb
import numpy as np
import pytest
from coulomb import errors


def ball() -> coulomb.Scene:
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.Particle(mass=1.0, position=(0.0, 0.1)))
    f = s.add(coulomb.HalfSpace())
    s.contact(s.attach(b, coulomb.Point()), f, mu=0.2, e=0.5)
    return s


def model() -> coulomb.Model:
    return coulomb.Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 0.1],
                         force=lambda q, v, t: np.array([0.0, -9.81]),
                         contacts=[coulomb.GapContact(gap=lambda q: q[1],
                                                      normal_jacobian=lambda q: [0, 1],
                                                      tangent_jacobian=lambda q: [[1, 0]],
                                                      mu=0.2)])


RUNS: dict[str, Callable[..., Any]] = {
    "scene": lambda **kw: ball().simulate(0.01, 1e-3, **kw),
    "model": lambda **kw: model().simulate(0.01, 1e-3, **kw),
}

# (keywords, error class, words the message must hold)
BAD = [
    ({"drift": "x"}, errors.InvalidParameterError, ("drift", "'bias'", "'x'")),
    ({"drift": 3}, errors.ArgumentTypeError, ("drift", "'projection'", "3")),
    ({"drift": None}, errors.ArgumentTypeError, ("drift", "None")),
    ({"restitution": "elastic"}, errors.InvalidParameterError, ("restitution", "'poisson'")),
    ({"restitution": b"newton"}, errors.ArgumentTypeError, ("restitution", "'newton'")),
    ({"drift_bias": "a"}, errors.ArgumentTypeError, ("drift_bias", "real number", "str")),
    ({"drift_bias": True}, errors.ArgumentTypeError, ("drift_bias", "real number", "bool")),
    ({"drift_bias": None}, errors.ArgumentTypeError, ("drift_bias", "NoneType")),
    ({"drift_bias": 0.0, "drift": "bias"}, errors.InvalidParameterError, ("drift_bias", "(0, 1]")),
    # out of range with another correction: refused, not silently ignored
    ({"drift_bias": 5.0}, errors.InvalidParameterError, ("drift_bias", "(0, 1]", "5")),
    ({"drift_bias": float("nan")}, errors.InvalidParameterError, ("drift_bias", "NaN")),
]


@pytest.mark.parametrize("run", sorted(RUNS))
@pytest.mark.parametrize(("kwargs", "exc", "words"), BAD)
def test_stepper_options_are_refused_by_the_core_naming_the_keyword(
        run: str, kwargs: dict[str, Any], exc: type, words: tuple[str, ...]) -> None:
    with pytest.raises(exc) as info:
        RUNS[run](**kwargs)
    if exc is errors.ArgumentTypeError:
        assert isinstance(info.value, TypeError)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


@pytest.mark.parametrize("run", sorted(RUNS))
@pytest.mark.parametrize("kwargs", [
    {"drift": "bias", "drift_bias": 1},  # an int is a real number
    {"drift": "bias", "drift_bias": np.float32(0.5)},
    {"drift": "projection"},
    {"restitution": "poisson"},
])
def test_good_stepper_options_are_taken(run: str, kwargs: dict[str, Any]) -> None:
    tr = RUNS[run](**kwargs)
    # the particle starts 0.1 above the floor at rest and falls 0.01 s: it stays above it
    assert float(np.min(tr.q[:, 1])) > 0.09
