r"""Joints: bilateral constraints between two bodies, or a body and the world, in the same
impulse step as the contacts.

>>> import coulomb
>>> scene = coulomb.Scene(dim=2, gravity=(0.0, -9.81))
>>> bob = scene.add(coulomb.RigidBody2D(mass=1.0, inertia=0.01, position=(1.0, 0.0)))
>>> hinge = scene.add(coulomb.Revolute(bob, None, anchor=(0.0, 0.0)))
>>> tr = scene.simulate(t_end=0.5, h=1e-3)
>>> import math
>>> abs(math.hypot(*tr.q[-1, :2]) - 1.0) < 1e-12  # the bob stays 1 m from the pivot
True

Each joint is a set of rows ``C(q) = 0`` whose velocity form ``J v = 0`` enters every step's
momentum balance beside the contacts: ``M (v_{k+1} - v_free) = J^T lambda + G P``. The joint
impulse is eliminated exactly per island of jointed bodies (the contact problem is solved with
the constrained inverse mass ``M^-1 - M^-1 J^T (J M^-1 J^T)^+ J M^-1``, so NSGS, the robust
mode and Lemke all solve scenes with joints unchanged); closed loops (a four-bar linkage) have
rows that depend on the others, found and dropped by a rank-revealing factorization. Each row
carries its second-order remainder over the step, and after each step a mass-weighted
projection brings ``C(q)`` back to rounding (velocities untouched).

Kinds (``a`` is the first body, ``b`` the second or the world; anchor and axis are world
values at the scene's initial state):

- :class:`Revolute`: a hinge about ``axis`` through ``anchor`` (2D: about the plane's normal,
  no axis); limits bound the angle (2D: ``theta_a - theta_b``; 3D: the turn of a relative to
  b about the axis since the initial state, within ``[-pi, pi]``).
- :class:`Prismatic`: a slider along ``axis``, no turning; limits bound the slide of a's anchor
  from b's along the axis (0 at the initial state).
- :class:`Spherical` (3D): a ball joint at ``anchor``.
- :class:`Fixed` (also :class:`Weld`): no relative motion.

A limit is a unilateral row with Newton's restitution ``e``, like a frictionless contact: a
pendulum striking a stop at ``v^-`` leaves it at ``-e v^-``.

Measured (``tests/step_joints.rs``, ``tests/test_joints.py``): a pendulum released at 1.2 rad
has the elliptic-integral period to a relative 2.3e-6 at h = 2e-3 and 5.8e-7 at h = 1e-3
(second order); a double pendulum keeps its energy within 2.8 h m g l over 5 s; the joint
rows hold to 2.5e-14 over 10^5 steps with the projection (7.5e-4 without).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from . import _validate
from ._arguments import _vector
from .errors import ArgumentTypeError, InvalidParameterError

__all__ = ["Fixed", "Joint", "Prismatic", "Revolute", "Spherical", "Weld"]


def _limits(limits: Any) -> tuple[float, float] | None:
    if limits is None:
        return None
    if not isinstance(limits, (tuple, list)) or len(limits) != 2:
        raise ArgumentTypeError(f"limits must be a pair (lo, hi) or None, got {limits!r}")
    lo = _validate.real("limits[0]", limits[0], finite=False, data=True)
    hi = _validate.real("limits[1]", limits[1], finite=False, data=True)
    if not lo < hi:
        raise InvalidParameterError(f"limits must satisfy lo < hi, got ({lo}, {hi})")
    return (lo, hi)


class Joint:
    """Base class of the joints; use :class:`Revolute`, :class:`Prismatic`,
    :class:`Spherical` or :class:`Fixed`."""

    kind = ""
    takes_limits = False

    def __init__(
        self,
        body_a: Any,
        body_b: Any = None,
        *,
        anchor: Sequence[float],
        axis: Sequence[float] | None = None,
        limits: tuple[float, float] | None = None,
        e: float = 0.0,
    ) -> None:
        from .model import Body

        if not isinstance(body_a, Body):
            raise ArgumentTypeError(
                f"body_a must be a body, got {type(body_a).__name__}"
            )
        if body_b is not None and not isinstance(body_b, Body):
            raise ArgumentTypeError(
                f"body_b must be a body or None (the world), got {type(body_b).__name__}"
            )
        if body_b is body_a:
            raise InvalidParameterError("a joint cannot join a body to itself")
        self.body_a = body_a
        self.body_b = body_b
        arr = np.asarray(_validate.array(anchor, "anchor", None), dtype=float).reshape(-1)
        if arr.shape[0] not in (2, 3):
            raise InvalidParameterError(f"anchor must have 2 or 3 entries, got {arr.shape[0]}")
        self.anchor = _vector("anchor", arr, arr.shape[0])
        self.axis: list[float] | None = None
        if axis is not None:
            ax = np.asarray(_validate.array(axis, "axis", None), dtype=float).reshape(-1)
            self.axis = _vector("axis", ax, ax.shape[0])
            if not math.hypot(*self.axis) > 0.0:
                raise InvalidParameterError("the axis has zero length")
        self.limits = _limits(limits)
        if self.limits is not None and not self.takes_limits:
            raise InvalidParameterError(
                f"a {type(self).__name__} joint takes no limits (revolute and prismatic do)"
            )
        self.e = _validate.real("e", e, low=0.0, high=1.0, data=True)

    def _spec(self, dim: int, body_index: Callable[[Any], int]) -> dict[str, Any]:
        """The joint as the stepper reads it, checked against the scene (``body_index``: a
        body's index in the scene)."""

        def index(body: Any) -> int:
            try:
                return body_index(body)
            except InvalidParameterError:
                raise InvalidParameterError(
                    "a joint's body was not added to the scene") from None

        a = index(self.body_a)
        b = None if self.body_b is None else index(self.body_b)
        for body in (self.body_a, self.body_b):
            if body is not None and body.kind == "particle":
                raise InvalidParameterError("joints connect rigid bodies, not particles")
        anchor = _vector("anchor", self.anchor, dim)
        needs_axis = self.kind == "prismatic" or (self.kind == "revolute" and dim == 3)
        if needs_axis and self.axis is None:
            raise InvalidParameterError(f"a {type(self).__name__} joint in {dim}D needs an axis")
        if not needs_axis and self.axis is not None:
            raise InvalidParameterError(
                f"a {type(self).__name__} joint in {dim}D takes no axis"
            )
        axis = [] if self.axis is None else _vector("axis", self.axis, dim)
        if self.kind == "spherical" and dim != 3:
            raise InvalidParameterError("a spherical joint needs dim = 3")
        if (self.limits is not None and self.kind == "revolute" and dim == 3
                and (self.limits[0] < -math.pi or self.limits[1] > math.pi)):
            raise InvalidParameterError(
                f"a 3D revolute's limits lie in [-pi, pi], got {self.limits}"
            )
        return {"kind": self.kind, "a": a, "b": b, "anchor": anchor, "axis": axis,
                "limits": self.limits, "e": self.e}


class Revolute(Joint):
    """A hinge: body a turns relative to body b (or the world) about ``axis`` through
    ``anchor`` (2D: about the plane's normal; give no axis). ``limits=(lo, hi)`` bounds the
    angle (2D: ``theta_a - theta_b``; 3D: the turn since the initial state about the axis),
    with Newton restitution ``e`` at the stops."""

    kind = "revolute"
    takes_limits = True


class Prismatic(Joint):
    """A slider: body a translates relative to body b (or the world) along ``axis``, without
    turning. ``limits=(lo, hi)`` bounds the slide of a's anchor from b's along the axis (0 at
    the initial state), with Newton restitution ``e`` at the stops."""

    kind = "prismatic"
    takes_limits = True


class Spherical(Joint):
    """A ball joint (3D): body a turns about ``anchor`` relative to body b (or the world)."""

    kind = "spherical"


class Fixed(Joint):
    """A weld: body a keeps its pose relative to body b (or the world)."""

    kind = "fixed"


Weld = Fixed
