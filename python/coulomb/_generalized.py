"""User-defined models in generalized coordinates: ``M(q)``, forces and gap functions given in
Python, stepped by the same impulse step as scenes (a Python loop around the Rust contact
solver)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core, _validate
from ._arguments import Solver, _dim, _positive, _solver_options, _steps, _vector
from .errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
    ProblemTooLargeError,
    ShapeError,
)
from .trajectory import Trajectory

__all__ = ["GapContact", "Model"]


def _numeric_jacobian(fun: Callable[[np.ndarray], Any], q: np.ndarray, rows: int) -> np.ndarray:
    """Central differences of ``fun`` at q, step ``1e-6 max(1, |q_i|)`` per coordinate."""
    jac = np.empty((rows, q.size))
    for i in range(q.size):
        d = 1e-6 * max(1.0, abs(q[i]))
        qp, qm = q.copy(), q.copy()
        qp[i] += d
        qm[i] -= d
        jac[:, i] = (np.atleast_1d(fun(qp)) - np.atleast_1d(fun(qm))).reshape(rows) / (2 * d)
    return jac


@dataclass(eq=False)
class GapContact:
    """A contact of a generalized-coordinate :class:`Model`: the gap ``g(q)`` (> 0 when
    separated), its normal Jacobian ``J_n(q) = dg/dq`` (``nv`` entries; central differences of
    ``gap`` when omitted), and for friction either the tangential Jacobian ``J_t(q)``
    (``(dim - 1, nv)``) or a tangential position ``s(q)`` (``dim - 1`` entries) whose central
    differences give it. ``mu >= 0`` and Newton's ``e`` in [0, 1]."""

    gap: Callable[[np.ndarray], float]
    normal_jacobian: Callable[[np.ndarray], Any] | None = None
    tangent_jacobian: Callable[[np.ndarray], Any] | None = None
    tangent_position: Callable[[np.ndarray], Any] | None = None
    mu: float = 0.0
    e: float = 0.0


class Model:
    r"""A model in generalized coordinates q (``v = dq/dt``, so ``nq = nv``):

    ``M(q) dv = f(q, v, t) dt + J_n^T dP_n + J_t^T dP_t``

    with the mass matrix ``mass_matrix`` (an SPD array or a callable ``M(q)``), the forces
    ``force(q, v, t)`` (default none) and the contacts (:class:`GapContact`). The same impulse
    step as :meth:`Scene.simulate`, run as a Python loop around the Rust contact solver
    (:func:`coulomb.contact.solve`). ``potential(q)`` (optional) adds the potential energy to
    the trajectory's total energy.
    """

    def __init__(
        self,
        dim: int,
        mass_matrix: Any,
        q0: Sequence[float],
        v0: Sequence[float] | None = None,
        force: Callable[[np.ndarray, np.ndarray, float], Any] | None = None,
        contacts: Sequence[GapContact] = (),
        potential: Callable[[np.ndarray], float] | None = None,
    ) -> None:
        _dim(dim)
        self.dim = int(dim)
        if q0 is None:
            raise ArgumentTypeError("q0 must be an array of real numbers, got None")
        q = _validate.array(q0, "q0", None).reshape(-1)
        self.q0 = np.asarray(_vector("q0", q, q.size))
        n = self.q0.size
        self.v0 = np.asarray(_vector("v0", v0 if v0 is not None else np.zeros(n), n))
        self.mass_matrix = mass_matrix
        self.force = force
        self.potential = potential
        for i, c in enumerate(contacts):
            if not isinstance(c, GapContact):
                raise ArgumentTypeError(f"contact {i} must be a GapContact, got {c!r}")
            _validate.real(f"contact {i}'s mu", c.mu, low=0.0)
            _validate.real(f"contact {i}'s e", c.e, low=0.0, high=1.0)
            if not callable(c.gap):
                raise ArgumentTypeError(f"contact {i}'s gap must be a function of q")
            if c.mu > 0 and c.tangent_jacobian is None and c.tangent_position is None:
                raise InvalidParameterError(
                    f"contact {i} has friction: give tangent_jacobian or tangent_position")
        self.contacts = list(contacts)
        self._mass(self.q0)  # checked before any work

    def _mass(self, q: np.ndarray) -> np.ndarray:
        m = self.mass_matrix(q) if callable(self.mass_matrix) else self.mass_matrix
        m = np.asarray(m, dtype=np.float64)
        n = q.size
        if m.shape != (n, n):
            raise ShapeError(f"M(q) must be {n} x {n}, got {m.shape}")
        if not np.all(np.isfinite(m)):
            raise NonFiniteError("M(q) has a non-finite entry")
        if not np.allclose(m, m.T, rtol=1e-10, atol=0.0):
            raise InvalidParameterError("M(q) must be symmetric")
        try:
            np.linalg.cholesky(m)
        except np.linalg.LinAlgError as exc:
            raise InvalidParameterError("M(q) must be positive definite") from exc
        return m

    def _frame(self, c: GapContact, q: np.ndarray) -> tuple[float, np.ndarray]:
        """The gap and the rows ``[J_n; J_t]`` (dim x nv) of one contact at q."""
        n = q.size
        i = next(k for k, x in enumerate(self.contacts) if x is c)
        try:
            g = float(c.gap(q))
        except (TypeError, ValueError) as exc:
            raise ArgumentTypeError(
                f"contact {i}'s gap function must return a real number: {exc}") from None
        if not math.isfinite(g):
            raise NonFiniteError(
                f"contact {i}'s gap function returned {g} at q = {q.tolist()}")
        rows = np.zeros((self.dim, n))
        try:
            rows[0] = (_validate.array(c.normal_jacobian(q), f"contact {i}'s normal_jacobian",
                                       None).reshape(n)
                       if c.normal_jacobian is not None else _numeric_jacobian(c.gap, q, 1)[0])
            if c.tangent_jacobian is not None:
                rows[1:] = _validate.array(c.tangent_jacobian(q),
                                           f"contact {i}'s tangent_jacobian",
                                           None).reshape(self.dim - 1, n)
            elif c.tangent_position is not None:
                rows[1:] = _numeric_jacobian(c.tangent_position, q, self.dim - 1)
        except ValueError as exc:
            if isinstance(exc, (ShapeError, InvalidParameterError)):
                raise
            raise ShapeError(f"contact {i}: the Jacobian rows must be {self.dim} x {n} "
                             f"(J_n: {n} entries, J_t: {self.dim - 1} x {n}): {exc}") from None
        if not np.all(np.isfinite(rows)):
            raise NonFiniteError(
                f"contact {i}'s Jacobian rows [J_n; J_t] have a non-finite entry at "
                f"q = {q.tolist()}")
        return g, rows

    def simulate(
        self,
        t_end: float,
        h: float,
        solver: Solver = "nsgs",
        *,
        tol: float | None = None,
        max_iter: int | None = None,
        facets: int | None = None,
        gap_tolerance: float = 1e-9,
        warm_start: bool = True,
        fallback: bool = True,
    ) -> Trajectory:
        """Runs ``ceil(t_end / h)`` impulse steps; options as :meth:`Scene.simulate`."""
        from . import contact as _contact

        t_end, h = _positive("t_end", t_end), _positive("h", h)
        steps = _steps(t_end, h)
        solver, tol, max_iter, _, facets = _solver_options(
            self.dim, solver, tol, max_iter, 1.0, facets)
        gap_tolerance = _validate.real("gap_tolerance", gap_tolerance, low=0.0)
        warm_start = _validate.boolean("warm_start", warm_start)
        fallback = _validate.boolean("fallback", fallback)
        row_bytes = 8 * (2 * self.q0.size + 16)
        if (steps + 1) * row_bytes > _core.memory_budget():
            raise ProblemTooLargeError(
                f"recording {steps + 1} states of {self.q0.size} coordinates needs about "
                f"{(steps + 1) * row_bytes} bytes, over the memory budget of "
                f"{_core.memory_budget()} bytes (coulomb.set_memory_budget raises it): "
                "simulate a shorter span per call")
        dim, nc = self.dim, len(self.contacts)
        q, v = self.q0.copy(), self.v0.copy()
        warm = np.zeros((nc, dim))
        approach = np.zeros(nc)
        landed = np.zeros(nc, dtype=bool)
        rec: dict[str, list[Any]] = {k: [] for k in (
            "t", "q", "v", "kinetic_energy", "potential_energy", "min_gap", "negative_gaps",
            "active", "status", "error", "scaled_error", "iterations", "momentum_residual",
            "min_normal_impulse", "cone_violation", "complementarity", "resumed", "fallback",
            "contact_step", "contact_id", "contact_impulse", "contact_velocity",
            "contact_approach", "contact_gap", "contact_closed", "load_power")}

        def push_state(t: float, m: np.ndarray, gaps: list[float]) -> None:
            rec["t"].append(t)
            rec["q"].append(q.copy())
            rec["v"].append(v.copy())
            rec["kinetic_energy"].append(0.5 * float(v @ m @ v))
            rec["potential_energy"].append(float(self.potential(q)) if self.potential else 0.0)
            rec["min_gap"].append(min(gaps, default=math.inf))
            rec["negative_gaps"].append(sum(g < -gap_tolerance for g in gaps))

        stopped = None
        m = self._mass(q)
        frames = [self._frame(c, q) for c in self.contacts]
        push_state(0.0, m, [g for g, _ in frames])
        for k in range(steps):
            t = k * h
            f = (np.asarray(self.force(q, v, t), dtype=np.float64).reshape(q.size)
                 if self.force else np.zeros(q.size))
            rec["load_power"].append(float(f @ v))
            v_free = v + h * np.linalg.solve(m, f)
            active = []
            for i, (g, rows) in enumerate(frames):
                vn_k, vn_free = float(rows[0] @ v), float(rows[0] @ v_free)
                # a contact owed the rebound of the impact the last step stopped stays active
                if g > gap_tolerance + 2 * h * max(0.0, -vn_k, -vn_free) and not landed[i]:
                    approach[i], landed[i], warm[i] = 0.0, False, 0.0
                    continue
                active.append((i, g, rows, vn_k, g <= gap_tolerance or bool(landed[i])))
            resumed = used_fallback = False
            v_next = v_free.copy()
            gp = np.zeros(q.size)
            status, err, iters, mn, cone, comp = "no_contact", 0.0, 0, 0.0, 0.0, 0.0
            serr = 0.0
            if active:
                G = np.vstack([rows for _, _, rows, _, _ in active])  # (dim na, nv)
                minv_gt = np.linalg.solve(m, G.T)
                W = G @ minv_gt
                W = 0.5 * (W + W.T)
                qc = G @ v_free
                used = []
                for a, (i, g, _, vn_k, closed) in enumerate(active):
                    if closed:
                        vminus = min(vn_k, approach[i], 0.0)
                        resumed = resumed or bool(landed[i])
                        qc[a * dim] += self.contacts[i].e * vminus
                        used.append(vminus)
                    else:
                        qc[a * dim] += g / h
                        used.append(vn_k)
                mus = np.array([self.contacts[i].mu for i, *_ in active])
                if np.all(qc[::dim] >= 0.0):
                    r = np.zeros(len(active) * dim)
                    status = "solved"
                else:
                    init = np.concatenate([warm[i] for i, *_ in active])
                    res = _contact.solve(W, qc, mus, dim=dim, method=solver, tol=tol,
                                         max_iter=max_iter, facets=facets,
                                         initial=init if (warm_start and solver == "nsgs")
                                         else None)
                    if not res.success and fallback and solver == "nsgs":
                        alt = _contact.solve(W, qc, mus, dim=dim, method="lemke",
                                             tol=max(tol, 1e-9))
                        if alt.scaled_error < res.scaled_error:
                            used_fallback = True
                            first_status, res = res.status, alt
                            if alt.scaled_error <= max(tol, 1e-9):
                                res["status"] = "solved"
                            elif alt.status == "solved":
                                # a polygon's answer (3D) that misses the exact cone
                                res["status"] = first_status
                    r = res.impulse.reshape(-1)
                    status, err, iters = res.status, res.error, res.iterations
                    serr = res.scaled_error
                    mn, cone = res.min_normal_impulse, res.cone_violation
                    comp = res.max_complementarity
                gp = G.T @ r
                v_next = v_free + minv_gt @ r
                for a, (i, g, rows, vn_k, closed) in enumerate(active):
                    p = r[a * dim:(a + 1) * dim]
                    warm[i] = p
                    # the impact record: made by an open contact that pushed, consumed by
                    # the next step, never replayed
                    landed[i] = not closed and p[0] > 0.0
                    approach[i] = min(vn_k, 0.0) if landed[i] else 0.0
                    rec["contact_step"].append(k)
                    rec["contact_id"].append(i)
                    rec["contact_impulse"].append(p.copy())
                    rec["contact_velocity"].append(rows @ v_next)
                    rec["contact_approach"].append(used[a])
                    rec["contact_gap"].append(g)
                    rec["contact_closed"].append(closed)
            mdv = m @ (v_next - v_free)
            scale = max(np.linalg.norm(gp), np.linalg.norm(m @ v_free),
                        np.linalg.norm(m @ v_next))
            res_norm = float(np.linalg.norm(mdv - gp))
            rec["momentum_residual"].append(res_norm / scale if scale > 1e-300 else res_norm)
            for key, val in (("active", len(active)), ("status", status), ("error", err),
                             ("scaled_error", serr),
                             ("iterations", iters), ("min_normal_impulse", mn),
                             ("cone_violation", cone), ("complementarity", comp),
                             ("resumed", resumed), ("fallback", used_fallback)):
                rec[key].append(val)
            v = v_next
            q = q + h * v
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                stopped = f"step {k} produced a non-finite state"
                break
            m = self._mass(q)
            frames = [self._frame(c, q) for c in self.contacts]
            push_state((k + 1) * h, m, [g for g, _ in frames])
        # f . v of the last state, for the step's energy E_h = T + V + (h/2) f . v (a stopped
        # run recorded one per state already: its last step's state was not kept)
        if stopped is None:
            f = (np.asarray(self.force(q, v, (len(rec["t"]) - 1) * h),
                            dtype=np.float64).reshape(q.size)
                 if self.force else np.zeros(q.size))
            rec["load_power"].append(float(f @ v))
        raw: dict[str, Any] = {"dim": dim, "stopped": stopped, "solve_time": float("nan")}
        for key, column in rec.items():
            if key in ("q", "v"):
                raw[key] = np.array(column, dtype=np.float64).reshape(len(column), q.size)
            elif key in ("contact_impulse", "contact_velocity"):
                raw[key] = np.array(column, dtype=np.float64).reshape(len(column), dim)
            elif key == "status":
                raw[key] = list(column)
            elif key in ("resumed", "fallback", "contact_closed"):
                raw[key] = np.array(column, dtype=bool)
            elif key in ("active", "iterations", "negative_gaps", "contact_step", "contact_id"):
                raw[key] = np.array(column, dtype=np.int64)
            else:
                raw[key] = np.array(column, dtype=np.float64)
        return Trajectory._from_core(raw, scene=None, h=h, solver=solver,
                                     gap_tolerance=gap_tolerance, tol=tol)
