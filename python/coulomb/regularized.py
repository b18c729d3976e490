"""Regularized (smoothed) friction on a ramp, integrated by a stiff ODE solver, for comparison.

Satici, *Kinematics and Machine Dynamics*, ch. 11 (section "Smoothing changes the sticking
behavior"), following Stewart (2000), replaces the set-valued law
``m v' in F_t - mu N Sign(v)`` by the smooth curve

    f_t = -mu N tanh(v / eps).

For a block on a ramp at angle ``theta`` (``s`` measured down the slope, ``N = m g0 cos(theta)``)
this is the ODE

    s' = v,   v' = g0 sin(theta) - mu g0 cos(theta) tanh(v / eps),

which cannot stick: where the exact law holds the block still (``tan(theta) <= mu``) the smooth
one settles on the creep velocity ``v* = eps artanh(tan(theta) / mu)`` instead, and a smaller
``eps`` makes the ODE stiff (its Jacobian near ``v*`` is
``-mu g0 cos(theta) sech^2(v*/eps) / eps``).
:func:`simulate_ramp` integrates it with :func:`scipy.integrate.solve_ivp` and reports the cost
(right-hand-side and Jacobian evaluations, LU factorizations) so the creep and the cost of
shrinking ``eps`` can be measured against :func:`coulomb_ramp`, the exact Coulomb answer.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ._extras import require
from ._result import Result
from ._status import Status
from .errors import InvalidParameterError, NonFiniteError

__all__ = ["RegularizedResult", "coulomb_ramp", "creep_velocity", "simulate_ramp"]

STANDARD_GRAVITY = 9.81
_METHODS = ("Radau", "BDF", "LSODA", "RK45", "DOP853")


class RegularizedResult(Result):
    """The regularized ramp trajectory and what it cost.

    Fields: ``t``, ``s`` (distance down the slope), ``v``, ``creep_velocity`` (``v*``, or NaN
    when the ramp is too steep to hold the block), ``nfev``, ``njev``, ``nlu``,
    ``solve_time`` (s), ``success``, ``status``, ``message``, ``method``, ``eps``.
    """


def _check(name: str, value: float, *, positive: bool = False, nonneg: bool = False) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise NonFiniteError(f"{name} must be finite, got {value}")
    if positive and value <= 0:
        raise InvalidParameterError(f"{name} must be > 0, got {value}")
    if nonneg and value < 0:
        raise InvalidParameterError(f"{name} must be >= 0, got {value}")
    return value


def creep_velocity(theta: float, mu: float, eps: float) -> float:
    """``v* = eps artanh(tan(theta) / mu)``, the smooth law's steady slide where Coulomb sticks.

    NaN when ``tan(theta) >= mu`` (the block accelerates under both laws).
    """
    theta = _check("theta", theta)
    mu = _check("mu", mu, nonneg=True)
    eps = _check("eps", eps, positive=True)
    ratio = math.tan(theta) / mu if mu > 0 else math.inf
    if not abs(ratio) < 1.0:
        return math.nan
    return eps * math.atanh(ratio)


def coulomb_ramp(
    theta: float, mu: float, v0: float, t: np.ndarray | float, g0: float = STANDARD_GRAVITY
) -> tuple[np.ndarray, np.ndarray]:
    """The exact Coulomb answer ``(s(t), v(t))`` for a block sent down the ramp at ``v0 >= 0``.

    Sliding decelerates at ``a = g0 (mu cos(theta) - sin(theta))``; when ``a > 0`` the block stops
    at ``t* = v0 / a``, ``s* = v0^2 / (2 a)`` and sticks for ever (the chapter's ramp: 0.3321 m/s^2,
    3.011 s, 1.505 m for theta = 20 deg, mu = 0.4, v0 = 1 m/s).
    """
    theta = _check("theta", theta)
    mu = _check("mu", mu, nonneg=True)
    v0 = _check("v0", v0, nonneg=True)
    tt = np.asarray(t, dtype=float)
    a = g0 * (mu * math.cos(theta) - math.sin(theta))
    if a > 0:
        t_stop = v0 / a
        tc = np.minimum(tt, t_stop)
    else:
        tc = tt
    v = v0 - a * tc
    s = v0 * tc - 0.5 * a * tc**2
    return s, v


def simulate_ramp(
    theta: float,
    mu: float,
    v0: float,
    t_end: float,
    eps: float,
    *,
    g0: float = STANDARD_GRAVITY,
    method: str = "Radau",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    t_eval: np.ndarray | None = None,
) -> RegularizedResult:
    """Integrate the tanh-regularized ramp from ``s = 0``, ``v = v0`` to ``t_end``.

    ``method`` is a :func:`scipy.integrate.solve_ivp` method; the stiff ones (``"Radau"``,
    ``"BDF"``, ``"LSODA"``) get the analytic Jacobian. ``t_eval`` defaults to 1001 points.
    Needs scipy (the ``ode`` extra).
    """
    require("scipy.integrate", extra="ode", what="coulomb.regularized.simulate_ramp")
    from scipy.integrate import solve_ivp

    theta = _check("theta", theta)
    mu = _check("mu", mu, nonneg=True)
    v0 = _check("v0", v0)
    t_end = _check("t_end", t_end, positive=True)
    eps = _check("eps", eps, positive=True)
    g0 = _check("g0", g0, positive=True)
    rtol = _check("rtol", rtol, positive=True)
    atol = _check("atol", atol, positive=True)
    if method not in _METHODS:
        raise InvalidParameterError(f"method must be one of {_METHODS}, got {method!r}")
    drive = g0 * math.sin(theta)
    grip = mu * g0 * math.cos(theta)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1], drive - grip * math.tanh(y[1] / eps)])

    def jac(_t: float, y: np.ndarray) -> np.ndarray:
        sech = 1.0 / math.cosh(min(abs(y[1]) / eps, 350.0))
        return np.array([[0.0, 1.0], [0.0, -grip * sech * sech / eps]])

    if t_eval is None:
        t_eval = np.linspace(0.0, t_end, 1001)
    options = {"jac": jac} if method in ("Radau", "BDF", "LSODA") else {}
    start = time.perf_counter()
    sol = solve_ivp(
        rhs, (0.0, t_end), [0.0, v0], method=method, rtol=rtol, atol=atol, t_eval=t_eval, **options
    )
    elapsed = time.perf_counter() - start
    return RegularizedResult(
        t=sol.t,
        s=sol.y[0],
        v=sol.y[1],
        creep_velocity=creep_velocity(theta, mu, eps),
        nfev=int(sol.nfev),
        njev=int(sol.njev),
        nlu=int(sol.nlu),
        solve_time=elapsed,
        success=bool(sol.success),
        status=Status.SOLVED if sol.success else Status.FAILED,
        message=str(sol.message),
        method=method,
        eps=eps,
    )
