"""Painleve's problem: which smooth contact modes a sliding rod admits.

The rod of Satici, *Kinematics and Machine Dynamics*, ch. 11 (section "Painleve's problem: a
sliding rod", after Stewart 2000) leans up and to the right from its lower end, which touches
the floor. The angle ``theta`` is measured from the horizontal, the rod
has mass ``m``, length ``l`` and central inertia ``J``. With a contact force ``(F, N)`` (tangential,
normal) at the lower end,

    m x'' = F,   m y'' = N - m g0,   J theta'' = (l/2) (F sin(theta) - N cos(theta)),

and the contact point ``(x_c, y_c) = (x - (l/2) cos(theta), y - (l/2) sin(theta))`` accelerates as

    [g'' ; x_c''] = K [N ; F] + [b ; c],      k = l^2 / (4 J),
    K = [[1/m + k cos^2,  -k sin cos],  [-k sin cos,  1/m + k sin^2]],
    b = (l/2) sin(theta) theta'^2 - g0,       c = (l/2) cos(theta) theta'^2,

where ``g = y_c`` is the gap. Sliding in the direction ``s = sign(x_c')`` sets ``F = -s mu N``,
so ``g'' = A N + b`` with

    A = 1/m + k cos(theta) (cos(theta) + s mu sin(theta))

(for sliding to the left, s = -1: ``A = 1/m - (l^2/4J) cos(theta) (mu sin(theta) - cos(theta))``).
At a closed contact with zero normal velocity the smooth modes must satisfy
``0 <= g'' perp N >= 0``. If ``A < 0`` and ``b < 0`` no mode exists (the chapter's figures:
``A = -0.5``, ``b = -9.81`` for m = 1, l = 1, J = 1/12, mu = 2, theta = 45 deg), and if
``A < 0 < b`` two exist: the force-level model fails, and an impulse (a jam) is needed. The
impulse time stepper of :mod:`coulomb` resolves both cases; this module tells a user which case
they are in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _validate
from ._result import Result
from .errors import InvalidParameterError

__all__ = ["PainleveAnalysis", "PainleveRod"]

STANDARD_GRAVITY = 9.81


class PainleveAnalysis(Result):
    """The smooth contact modes a rod state admits.

    Fields: ``A`` (the A above for the sliding direction, or NaN when the contact point does not
    slide), ``b``, ``slip`` (the contact point's tangential velocity), ``modes`` (a dict from each
    consistent mode, ``"lift-off"``, ``"stick"``, ``"slide-left"``, ``"slide-right"``, to its
    ``(N, F)``), ``consistent`` (at least one mode), ``unique`` (exactly one), ``message``.
    """


def _finite(name: str, value: float) -> float:
    return _validate.real(name, value, data=True)


@dataclass(frozen=True)
class PainleveRod:
    """A uniform or non-uniform rod touching a floor at its lower end.

    ``J`` defaults to the uniform rod's ``m l^2 / 12``. ``g0`` is gravitational acceleration.
    """

    m: float = 1.0
    l: float = 1.0
    mu: float = 2.0
    J: float | None = None
    g0: float = STANDARD_GRAVITY

    def __post_init__(self) -> None:
        for name in ("m", "l", "mu", "g0"):
            _finite(name, getattr(self, name))
        if self.J is not None:
            _finite("J", self.J)
        if self.m <= 0 or self.l <= 0:
            raise InvalidParameterError(f"m and l must be > 0, got m = {self.m}, l = {self.l}")
        if self.mu < 0:
            raise InvalidParameterError(f"mu must be >= 0, got {self.mu}")
        if self.J is not None and self.J <= 0:
            raise InvalidParameterError(f"J must be > 0, got {self.J}")

    @property
    def inertia(self) -> float:
        """The central inertia J (the uniform rod's ``m l^2 / 12`` unless given)."""
        return self.J if self.J is not None else self.m * self.l**2 / 12.0

    def contact_matrix(self, theta: float) -> np.ndarray:
        """K with ``[g'', x_c''] = K [N, F] + [b, c]`` (symmetric positive definite)."""
        k = self.l**2 / (4.0 * self.inertia)
        s, c = math.sin(theta), math.cos(theta)
        inv_m = 1.0 / self.m
        return np.array([[inv_m + k * c * c, -k * s * c], [-k * s * c, inv_m + k * s * s]])

    def A(self, theta: float, slip_direction: int = -1) -> float:
        """``A(theta)`` (module docstring) for sliding in ``slip_direction`` (-1: left, +1:
        right)."""
        if slip_direction not in (-1, 1):
            raise InvalidParameterError(f"slip_direction must be -1 or +1, got {slip_direction}")
        k = self.l**2 / (4.0 * self.inertia)
        s, c = math.sin(theta), math.cos(theta)
        return 1.0 / self.m + k * c * (c + slip_direction * self.mu * s)

    def b(self, theta: float, theta_dot: float = 0.0) -> float:
        """``b(theta, theta')``: the gap's acceleration with no contact force."""
        return 0.5 * self.l * math.sin(theta) * theta_dot**2 - self.g0

    def c(self, theta: float, theta_dot: float = 0.0) -> float:
        """The contact point's tangential acceleration with no contact force."""
        return 0.5 * self.l * math.cos(theta) * theta_dot**2

    def critical_mu(self, theta: float) -> float:
        """The friction coefficient above which ``A(theta) < 0`` when sliding left.

        ``mu_c = (1 / (m k cos(theta)) + cos(theta)) / sin(theta)``; for a uniform rod its
        minimum over theta is 4/3 (Painleve's classical bound).
        """
        theta = _finite("theta", theta)
        s, c = math.sin(theta), math.cos(theta)
        if s <= 0 or c <= 0:
            return math.inf
        k = self.l**2 / (4.0 * self.inertia)
        return (1.0 / (self.m * k * c) + c) / s

    def analyze(self, theta: float, theta_dot: float = 0.0, slip: float = -1.0) -> PainleveAnalysis:
        """The consistent smooth modes at a closed contact with zero normal velocity.

        ``slip`` is the contact point's tangential velocity ``x_c'``: when it is nonzero only
        sliding in its direction or lift-off can hold; when it is zero the contact may also stick
        or start to slide either way (with the tangential acceleration along the slide).
        """
        theta = _finite("theta", theta)
        theta_dot = _finite("theta_dot", theta_dot)
        slip = _finite("slip", slip)
        if not 0.0 < theta < math.pi / 2:
            raise InvalidParameterError(
                f"theta must lie in (0, pi/2) for a rod leaning on its lower end, got {theta}"
            )
        b = self.b(theta, theta_dot)
        c = self.c(theta, theta_dot)
        K = self.contact_matrix(theta)
        scale = max(abs(b), abs(c), self.g0, 1e-300)
        tol = 1e-12 * scale
        modes: dict[str, tuple[float, float]] = {}
        if b >= -tol:
            modes["lift-off"] = (0.0, 0.0)
        directions = [int(np.sign(slip))] if slip != 0.0 else [-1, 1]
        for s in directions:
            a = self.A(theta, s)
            if a == 0.0:
                continue
            n = -b / a
            f = -s * self.mu * n
            if n <= 0.0:
                continue
            if slip == 0.0:
                # starting to slide: the contact point must accelerate the way it slides
                xc_dd = K[1, 0] * n + K[1, 1] * f + c
                if s * xc_dd < -tol:
                    continue
            modes["slide-left" if s < 0 else "slide-right"] = (n, f)
        if slip == 0.0:
            n, f = np.linalg.solve(K, [-b, -c])
            if n >= 0.0 and abs(f) <= self.mu * n * (1 + 1e-12):
                modes["stick"] = (float(n), float(f))
        a_slide = self.A(theta, int(np.sign(slip))) if slip != 0.0 else math.nan
        if not modes:
            message = (
                "no smooth mode: sliding needs N < 0 and lift-off needs b >= 0 "
                "(Painleve inconsistency; an impulse must stop the slip)"
            )
        elif len(modes) > 1:
            message = f"{len(modes)} smooth modes ({', '.join(modes)}): the motion is not unique"
        else:
            message = f"one smooth mode: {next(iter(modes))}"
        return PainleveAnalysis(
            A=a_slide,
            b=b,
            slip=slip,
            modes=modes,
            consistent=bool(modes),
            unique=len(modes) == 1,
            message=message,
        )
