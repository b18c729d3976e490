"""The one vocabulary of how a solve, a step or a simulation ended: :class:`Status`."""

from __future__ import annotations

import enum


class Status(str, enum.Enum):
    """How a solve, a time step or a simulation ended.

    A ``str`` subclass: a member equals its value (``Status.SOLVED == "solved"``), formats as
    it (``f"{r.status}"`` gives ``solved``) and hashes as it, so code written against the
    plain strings keeps working. ``Status("solved")`` looks a member up by its value.

    Solvers (:func:`coulomb.lcp.solve`, :func:`coulomb.contact.solve`):

    ``SOLVED``
        The answer passed the tolerance on the original data.
    ``RAY_TERMINATION``
        Lemke ended on a secondary ray; for a copositive-plus M (e.g. positive semidefinite)
        this proves the LCP has no solution.
    ``PIVOT_LIMIT``
        Lemke ran out of pivots.
    ``ITERATION_LIMIT``
        An iterative method ran out of iterations before reaching the tolerance.
    ``NUMERICAL_FAILURE``
        A factorization or pivot was too ill-conditioned to trust.
    ``NO_SOLUTION``
        Enumeration examined every complementary basis and found no solution.

    Time steps (a trajectory's per-step ``solver_status``): a solver status above, or

    ``NO_CONTACT``
        No contact was active in the step, so there was nothing to solve.

    Simulations (a trajectory's ``status``) and the regularized ramp:

    ``COMPLETED``
        Every step ran and every contact solve was solved.
    ``STOPPED``
        The simulation stopped early (the message says why).
    ``SOLVER_FAILURES``
        Every step ran, but some contact solves missed their tolerance.
    ``FAILED``
        The ODE integrator of :func:`coulomb.regularized.simulate_ramp` failed.
    """

    SOLVED = "solved"
    RAY_TERMINATION = "ray_termination"
    PIVOT_LIMIT = "pivot_limit"
    ITERATION_LIMIT = "iteration_limit"
    NUMERICAL_FAILURE = "numerical_failure"
    NO_SOLUTION = "no_solution"
    NO_CONTACT = "no_contact"
    COMPLETED = "completed"
    STOPPED = "stopped"
    SOLVER_FAILURES = "solver_failures"
    FAILED = "failed"

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    def __repr__(self) -> str:
        return f"Status.{self.name}"


#: each member by its value, for the core's results (a dict lookup instead of ``Status(v)``,
#: whose ``Enum.__call__`` costs about 0.5 us)
BY_VALUE: dict[str, Status] = {member.value: member for member in Status}
