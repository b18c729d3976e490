"""The named studies of ``coulomb study NAME`` (:data:`PRESETS`) and their runs: module-level
functions, so that any executor's workers can import them. :mod:`coulomb.study` re-exports
them (``coulomb.study.ramp``, ...) and runs a preset with :func:`coulomb.study.run_preset`."""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np

__all__ = [
    "PRESETS",
    "contact_tolerance",
    "floor_impact",
    "nsgs_tolerance",
    "painleve_jam",
    "ramp",
    "regularized_ramp",
]


def regularized_ramp(
    eps: float = 1e-3,
    method: str = "Radau",
    rtol: float = 1e-8,
    theta_deg: float = 20.0,
    mu: float = 0.4,
    v0: float = 1.0,
    t_end: float = 10.0,
) -> dict[str, float]:
    """The chapter's ramp under the tanh-smoothed law: ``creep`` is how far past the exact Coulomb
    stop (1.505 m) the block has gone at ``t_end``; ``nfev`` the ODE solver's cost."""
    from .regularized import coulomb_ramp, simulate_ramp

    theta = math.radians(theta_deg)
    res = simulate_ramp(theta, mu, v0, t_end, eps, method=method, rtol=rtol, atol=rtol * 1e-2)
    s_exact, _ = coulomb_ramp(theta, mu, v0, np.array([t_end]))
    return {"creep": float(res.s[-1] - s_exact[0]), "nfev": res.nfev, "njev": res.njev}


def contact_tolerance(
    tol: float = 1e-8, method: Literal["nsgs", "lemke", "prox"] = "nsgs", facets: int = 8
) -> dict[str, float]:
    """The chapter's oblique inelastic impact in 3D (m = 2, v = (-3, 1, 0), mu = 0.2) with slip
    at 30 deg off the first tangent, solved at tolerance ``tol``: returns the post-step slip
    speed ``u_t`` (exactly 0.4) and the solver's work."""
    from . import contact

    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    options: dict[str, Any] = {"tol": tol}
    if method == "lemke":
        options["facets"] = facets
    r = contact.solve(np.eye(3) / 2.0, [-3.0, c, s], 0.2, dim=3, method=method, **options)
    u = r.velocity[0]
    return {
        "u_t": float(math.hypot(u[1], u[2])),
        "u_n": float(u[0]),
        "iterations": int(r.get("iterations", r.get("pivots", 0)) or 0),
        "success": bool(r.success),
    }


def _stack_problem(nc: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A reproducible 3D contact problem: W = J M^-1 J^T for nc contacts on a chain of bodies
    (each contact couples two neighbouring bodies, like a stack), q pushing them together
    with some slip."""
    rng = np.random.default_rng(seed)
    nb = nc + 1
    J = np.zeros((3 * nc, 6 * nb))
    for i in range(nc):
        frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        arm = rng.normal(scale=0.1, size=3)
        for body, sign in ((i, 1.0), (i + 1, -1.0)):
            lin = sign * frame.T
            ang = (
                sign
                * frame.T
                @ np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]]).T
            )
            J[3 * i : 3 * i + 3, 6 * body : 6 * body + 3] = lin
            J[3 * i : 3 * i + 3, 6 * body + 3 : 6 * body + 6] = ang
    minv = np.diag(np.tile([1.0, 1.0, 1.0, 6.0, 6.0, 6.0], nb))
    W = J @ minv @ J.T
    q = rng.normal(size=3 * nc)
    q[0::3] = -np.abs(q[0::3]) - 0.5
    return W, q


def nsgs_tolerance(
    tol: float = 1e-8, nc: int = 12, seed: int = 1, mu: float = 0.5
) -> dict[str, Any]:
    """A chain of ``nc`` frictional contacts (see ``_stack_problem``) solved by NSGS at ``tol``:
    returns the total normal impulse and total slip speed (compare with a run at tol 1e-14)
    and the sweeps it took."""
    from . import contact

    W, q = _stack_problem(nc, seed)
    r = contact.solve(W, q, mu, dim=3, method="nsgs", tol=tol, max_iter=100_000)
    u = r.velocity
    return {
        "normal_impulse": float(r.impulse[:, 0].sum()),
        "slip": float(np.hypot(u[:, 1], u[:, 2]).sum()),
        "iterations": int(r.iterations),
        "solver_error": float(r.error),
    }


def ramp(
    h: float = 1e-3,
    solver: Literal["nsgs", "lemke"] = "nsgs",
    tol: float | None = None,
    facets: int | None = None,
    warm_start: bool = True,
    max_iter: int | None = None,
    drift: str = "none",
    t_end: float = 4.0,
) -> dict[str, Any]:
    """The chapter's ramp (20 deg, mu = 0.4, v0 = 1 m/s down the slope) stepped at ``h``:
    ``stop_distance`` (exact 1.5053 m), ``stop_time`` (exact 3.0112 s), ``creep`` (motion after
    the stop; exact 0) and the stepper's work. Every setting a user trades is an argument:
    step, solver, tolerance, facets, warm start, iteration limit, drift correction."""
    from .model import HalfSpace, Particle, Point, Scene

    th = math.radians(20.0)
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    block = scene.add(
        Particle(mass=1.0, position=(0.0, 0.0), velocity=(math.cos(th), -math.sin(th)))
    )
    scene.contact(scene.attach(block, Point()), scene.add(HalfSpace.ramp(20.0)), mu=0.4)
    tr = scene.simulate(
        t_end,
        h,
        solver,
        tol=tol,
        facets=facets,
        warm_start=warm_start,
        max_iter=max_iter,
        drift=drift,  # type: ignore[arg-type]
    )
    still = np.flatnonzero(np.all(np.abs(tr.v) < 1e-12, axis=1))
    k = int(still[0]) if len(still) else len(tr.t) - 1
    s = tr.q[:, 0] * math.cos(th) - tr.q[:, 1] * math.sin(th)
    return {
        "stop_distance": float(s[k]),
        "stop_time": float(tr.t[k]),
        "creep": float(abs(s[-1] - s[k])),
        "iterations": int(np.sum(tr.iterations)),
        "success": bool(tr.success),
    }


def painleve_jam(h: float = 1e-3, solver: str = "nsgs") -> dict[str, Any]:
    """The chapter's Painleve rod (m = 1, l = 1, J = 1/12, mu = 2, 45 deg, end sliding left at
    1 m/s): the first step's impulse, which jams the end. Its limit as h -> 0 stops the end
    exactly: ``P_n = 0.375``, ``P_t = 0.625`` N s."""
    from .model import HalfSpace, RigidBody2D, Scene, Segment

    th = math.radians(45.0)
    scene = Scene(dim=2, gravity=(0.0, -9.81))
    rod = scene.add(
        RigidBody2D(
            mass=1.0,
            inertia=1.0 / 12.0,
            position=(0.0, 0.5 * math.sin(th)),
            angle=th,
            velocity=(-1.0, 0.0),
        )
    )
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(rod, Segment((-0.5, 0.0), (0.5, 0.0))), floor, mu=2.0)
    tr = scene.simulate(3 * h, h, solver)  # type: ignore[arg-type]
    first = tr.contact_step == 0
    pn, pt = tr.contact_impulse[first][0]
    return {"P_n": float(pn), "P_t": float(pt), "success": bool(tr.success)}


def floor_impact(h: float = 1e-3, phase: float = 0.3, speed: float = 3.0) -> dict[str, Any]:
    """The chapter's floor impact (m = 0.5 kg, e = 0.6) at ``speed`` m/s, the impact falling
    ``phase`` of the way into a step: the rebound (exact: ``0.6 speed``) and impulse (exact:
    ``0.8 speed`` N s)."""
    from .model import HalfSpace, Particle, Point, Scene

    scene = Scene(dim=2, gravity=(0.0, 0.0))
    ball = scene.add(Particle(mass=0.5, position=(0.0, phase * speed * h), velocity=(0.0, -speed)))
    scene.contact(scene.attach(ball, Point()), scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0))), e=0.6)
    tr = scene.simulate(4 * h, h)
    return {
        "rebound": float(tr.v[-1, 1]),
        "impulse": float(tr.contact_impulse[:, 0].sum()),
        "success": bool(tr.success),
    }


#: Named studies for ``coulomb study NAME``: the run, its grid, its reference, and the
#: setting whose convergence order is reported.
PRESETS: dict[str, dict[str, Any]] = {
    "facets": {
        "run": contact_tolerance,
        # powers of two keep the slip (30 deg) a third of a facet spacing from the nearest
        # direction, so the error measures the spacing alone (12 or 24 facets contain 30 deg
        # and are exact)
        "grid": {"method": ["lemke"], "facets": [4, 8, 16, 32, 64, 128]},
        "reference": {"u_t": 0.4},
        "order": "facets",
        "about": "polyhedral cone on the chapter's oblique impact: slip error against facets",
    },
    "nsgs-tolerance": {
        "run": nsgs_tolerance,
        "grid": {"tol": [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10, 1e-12]},
        "reference_settings": {"tol": 1e-14},
        "quantities": ["normal_impulse"],
        "order": "tol",
        "about": "NSGS on a 12-contact chain: impulse error against tolerance",
    },
    "ramp-h": {
        "run": ramp,
        "grid": {"h": [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], "solver": ["nsgs", "lemke"]},
        "reference": {
            "stop_distance": 1.0
            / (2.0 * 9.81 * (0.4 * math.cos(math.radians(20.0)) - math.sin(math.radians(20.0))))
        },
        "order": "h",
        "order_where": {"solver": "nsgs"},
        "about": "the chapter's ramp: stop-distance error against step size and solver",
    },
    "impact-h": {
        "run": floor_impact,
        "grid": {"h": [1e-1, 1e-2, 1e-3, 1e-4, 1e-5], "phase": [0.0, 0.3, 0.9]},
        "reference": {"rebound": 1.8, "impulse": 2.4},
        "order": "h",
        "about": "the chapter's floor impact (e = 0.6): rebound and impulse against step size and "
        "where in the step the impact falls (exact at every h)",
    },
    "painleve-h": {
        "run": painleve_jam,
        "grid": {"h": [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5]},
        "reference": {"P_n": 0.375, "P_t": 0.625},
        "order": "h",
        "about": "Painleve's rod: the jam impulse against step size (limit 0.375, 0.625 N s)",
    },
    "regularized-ramp": {
        "run": regularized_ramp,
        "grid": {"eps": [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], "method": ["Radau", "RK45"]},
        "reference": {"creep": 0.0},
        "order": "eps",
        "order_where": {"method": "Radau"},
        "about": "tanh-smoothed friction on the chapter's ramp: creep against eps, ODE cost",
        # (module, extra): checked before the study starts
        "needs": [("scipy.integrate", "ode")],
    },
}
