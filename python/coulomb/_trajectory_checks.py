"""The per-step checks of a :class:`coulomb.trajectory.Trajectory` (see
:meth:`coulomb.trajectory.Trajectory.check`, whose documentation states the rules)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._readable import readable
from ._result import Result

if TYPE_CHECKING:
    from .trajectory import Trajectory

#: the tolerance of a step's error_q half when the solver's tol is tighter (Rust
#: ``step::solve::STEP_ERROR_Q_TOL``: error_q follows stacked contacts less closely than
#: 1e-12).
STEP_ERROR_Q_TOL = 1e-9


def worst(tr: Trajectory) -> dict[str, float]:
    """The largest of each per-step measure over the trajectory."""

    def mx(a: np.ndarray) -> float:
        return float(np.max(a)) if len(a) else 0.0

    return {
        "momentum_residual": mx(tr.momentum_residual),
        "solver_error": mx(tr.solver_error),
        "solver_scaled_error": mx(tr.solver_scaled_error),
        "solver_error_q": mx(tr.solver_error_q),
        "cone_violation": mx(tr.cone_violation),
        "complementarity": mx(tr.complementarity),
        "energy_gain": float(np.max(energy_gain(tr), initial=0.0)),
    }


def energy_gain(tr: Trajectory) -> np.ndarray:
    """Per step, how much ``T + V`` rose beyond the loads' O(h) work of the step (see
    :meth:`coulomb.trajectory.Trajectory.energy_gain`)."""
    e, w = tr.total_energy, 0.5 * tr.h * tr.load_power
    gain = np.diff(e) - np.abs(np.diff(w))
    start = 0  # the state before the landing step of the current run of rebounds
    for k in map(int, np.flatnonzero(tr.resumed)):
        if k < 1:
            continue
        if not tr.resumed[k - 1]:
            start = k - 1
        ref = int(start + np.argmax(e[start:k + 1]))
        gain[k] = e[k + 1] - e[ref] - abs(w[k + 1] - w[ref])
    return gain


def energy_tolerance(tr: Trajectory, energy_tol: float) -> float:
    """``energy_tol`` times the trajectory's energy scale, the largest
    ``|T| + |V| + |(h/2) f . v|`` over its states (the terms ``E_h`` is summed from, so
    the rounding of ``E_h`` and of the contact solves' residuals is in proportion):
    unit-consistent, with no absolute floor."""
    t, p = tr.kinetic_energy, tr.potential_energy
    w = 0.5 * tr.h * tr.load_power
    if len(t) == 0:
        return 0.0
    return energy_tol * float(np.max(np.abs(t) + np.abs(p) + np.abs(w)))


def check(tr: Trajectory, *, momentum_tol: float, energy_tol: float,
          gap_tol: float | None) -> Result:
    """Every violation of the per-step checks, as a summary (the rules:
    :meth:`coulomb.trajectory.Trajectory.check`)."""
    v: list[str] = []
    if tr.stopped is not None:
        v.append(f"stopped early: {tr.stopped}")
    for name in ("q", "v", "contact_impulse"):
        if not np.all(np.isfinite(getattr(tr, name))):
            v.append(f"{name} has non-finite values")
    status = tr.solver_status
    bad = [(k, s) for k, s in enumerate(status) if s not in ("solved", "no_contact")]
    if bad:
        k, s = bad[0]
        v.append(f"{len(bad)} contact solves did not succeed (first: step {k}, {s}, "
                 f"scaled_error {readable(tr.solver_scaled_error[k])})")
    # the verdict's own rule on the recorded measure (see the docstring)
    exact = tr.solver != "lemke" or tr.dim == 2
    if exact:
        tol = np.where(tr.fallback, max(tr.tol, 1e-9), tr.tol)
        se = tr.solver_scaled_error
        solved = np.array([s == "solved" for s in status], dtype=bool)
        wrong = np.flatnonzero(solved & ~(se <= tol))
        if len(wrong):
            k = int(wrong[0])
            v.append(f"{len(wrong)} steps reported solved whose scaled_error exceeds tol "
                     f"(first: step {k}, {readable(se[k])} > {readable(tol[k])})")
        eq, floor = tr.solver_error_q, tr.solver_error_q_floor
        # a step's error_q half has the tolerance max(tol, 1e-9) (the core's
        # STEP_ERROR_Q_TOL: error_q follows stacked contacts less closely than 1e-12)
        allowed = np.maximum(np.maximum(tol, STEP_ERROR_Q_TOL), floor)
        wrong = np.flatnonzero(solved & ~(eq <= allowed))
        if len(wrong):
            k = int(wrong[0])
            v.append(f"{len(wrong)} steps reported solved whose error_q exceeds "
                     f"max(tol, error_q_floor) (first: step {k}, {readable(eq[k])} > "
                     f"{readable(allowed[k])})")
    res = tr.momentum_residual
    if np.any(res > momentum_tol):
        v.append(f"momentum residual up to {readable(res.max())} > {readable(momentum_tol)}")
    if gap_tol is None:
        gap_tol = tr.gap_tolerance
    gaps = tr.min_gap
    if np.any(gaps < -gap_tol):
        k = int(np.argmin(gaps))
        v.append(f"penetration: min gap {gaps[k]:.3e} m at t = {tr.t[k]:.6g} s "
                 f"({int(np.sum(gaps < -gap_tol))} states)")
    etol = energy_tolerance(tr, energy_tol)
    gain = energy_gain(tr)
    if np.any(gain > etol):
        k = int(np.argmax(gain))
        v.append(f"energy gained in {int(np.sum(gain > etol))} steps, up to "
                 f"{gain[k]:.3e} J (step {k}, t = {tr.t[k]:.6g} s)")
    return Result(ok=not v, violations=v, **worst(tr))
