"""User-defined models in generalized coordinates: ``M(q)``, forces and gap functions given in
Python, stepped by the scenes' impulse time stepper in Rust, which calls them back at each
state."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from . import _core, _validate
from ._arguments import Solver, _dim, _positive, _solver_options, _steps, _vector
from .errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
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
    ``force(q, v, t)`` (default none) and the contacts (:class:`GapContact`). Stepped by the
    same Rust impulse time stepper as :meth:`Scene.simulate` (the same contact search, impact
    laws, impact memory, drift options, fallback and per-step verdict), which calls these
    functions back at each state. ``potential(q)`` (optional) adds the potential energy to
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

    def _frame(self, i: int, q: np.ndarray) -> tuple[float, np.ndarray]:
        """The gap and the rows ``[J_n; J_t]`` (dim x nv) of contact i at q."""
        c = self.contacts[i]
        n = q.size
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

    # the callbacks of the Rust stepper (flat float64 arrays; errors raised here stop the
    # run and surface as they are)

    def _mass_values(self, q: np.ndarray) -> np.ndarray:
        """``M(q)`` row-major, its shape and values checked (symmetry and positive
        definiteness are checked by the stepper)."""
        m = self.mass_matrix(q) if callable(self.mass_matrix) else self.mass_matrix
        m = np.asarray(m, dtype=np.float64)
        n = q.size
        if m.shape != (n, n):
            raise ShapeError(f"M(q) must be {n} x {n}, got {m.shape}")
        if not np.all(np.isfinite(m)):
            raise NonFiniteError("M(q) has a non-finite entry")
        return np.ascontiguousarray(m).reshape(-1)

    def _force_values(self, q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        assert self.force is not None
        f = np.asarray(self.force(q, v, t), dtype=np.float64)
        if f.size != q.size:
            raise ShapeError(f"force(q, v, t) must have {q.size} entries, got shape {f.shape}")
        return np.ascontiguousarray(f).reshape(-1)

    def _contact_values(self, q: np.ndarray) -> np.ndarray:
        frames = [self._frame(i, q) for i in range(len(self.contacts))]
        return np.concatenate([np.array([g for g, _ in frames], dtype=np.float64)]
                              + [rows.reshape(-1) for _, rows in frames])

    def _potential_value(self, q: np.ndarray) -> float:
        assert self.potential is not None
        v = float(self.potential(q))
        if not math.isfinite(v):
            raise NonFiniteError(f"potential(q) returned {v} at q = {q.tolist()}")
        return v

    def simulate(
        self,
        t_end: float,
        h: float,
        solver: Solver = "nsgs",
        *,
        tol: float | None = None,
        max_iter: int | None = None,
        relaxation: float = 1.0,
        facets: int | None = None,
        gap_tolerance: float = 1e-9,
        warm_start: bool = True,
        fallback: bool = True,
        drift: Literal["none", "bias", "projection"] = "none",
        drift_bias: float = 0.2,
        restitution: Literal["newton", "poisson"] = "newton",
        record_every: int = 1,
        locate_impacts: bool = False,
    ) -> Trajectory:
        """Runs ``ceil(t_end / h)`` impulse steps; options as :meth:`Scene.simulate`
        (Newton's or Poisson's law, the drift corrections, the fallback, ``record_every``,
        ``locate_impacts``: an isolated impact's instant is found on the step's free path
        from the contacts' gap functions, called at the sampled and bisected instants, and
        the law is applied there with ``M`` and the Jacobian at that instant). The Rust
        stepper runs the loop and calls ``mass_matrix``, ``force``, the contacts' functions
        and ``potential`` back at each state (holding the GIL only then), and the contacts'
        functions once more in a step with active contacts, at the predicted state
        ``q + h v_free``, for the gaps' second-order term over the step (as scenes have); an
        exception raised in one of them stops the run and is raised as it is."""
        t_end, h = _positive("t_end", t_end), _positive("h", h)
        steps = _steps(t_end, h)
        solver, tol, max_iter, relaxation, facets = _solver_options(
            self.dim, solver, tol, max_iter, relaxation, facets)
        gap_tolerance = _validate.real("gap_tolerance", gap_tolerance, low=0.0)
        warm_start = _validate.boolean("warm_start", warm_start)
        fallback = _validate.boolean("fallback", fallback)
        # drift, drift_bias and restitution are checked by the core (type, value, range)
        record_every = _validate.count("record_every", record_every)
        locate_impacts = _validate.boolean("locate_impacts", locate_impacts)
        raw = _core.model_simulate(
            self.dim,
            [(float(c.mu), float(c.e)) for c in self.contacts],
            self._mass_values,
            self._force_values if self.force is not None else None,
            self._contact_values if self.contacts else None,
            self._potential_value if self.potential is not None else None,
            [float(x) for x in self.q0],
            [float(x) for x in self.v0],
            h, steps, solver=solver, tol=tol, max_iter=max_iter, relaxation=relaxation,
            facets=facets, gap_tolerance=gap_tolerance, warm_start=warm_start,
            fallback=fallback, drift=drift, drift_bias=drift_bias,
            restitution=restitution, record_every=record_every,
            locate_impacts=locate_impacts,
        )
        return Trajectory._from_core(raw, scene=None, h=h, solver=solver,
                                     record_every=record_every,
                                     gap_tolerance=gap_tolerance, tol=tol)
