r"""The result of :meth:`coulomb.Scene.simulate` (and :meth:`coulomb.Model.simulate`): a
:class:`Trajectory` holds the states, the impulses and the per-step checks of the impulse time
stepper (Stewart and Trinkle 1996; Stewart 2000): momentum balance, gaps, normal impulses,
friction cone, complementarity and energy.

The energy the impulse step keeps is not ``T + V`` but ``E_h = T + V + (h/2) f . v``: with
``v_{k+1} = v_k + h M^{-1} f + M^{-1} G P`` and ``x_{k+1} = x_k + h v_{k+1}``, the identity
``T(v_{k+1}) - T(v_k) = (v_k + v_{k+1})/2 . (h f + G P)`` for a constant M gives

``E_h(k+1) - E_h(k) = (v_k + v_{k+1})/2 . G P``,

the work of the contact impulses at the mean velocity (Moreau's energy balance), which is
``<= 0`` for an impact with ``e <= 1`` and for Coulomb friction that dissipates. ``T + V``
itself moves by ``-(h/2) f . (v_{k+1} - v_k)`` more: the loads' O(h) work over the step, about
``m g h |v_n|`` at each bounce under gravity (``T + V`` rises when the ball leaves the floor
and falls back in flight), which is the integrator's and not a gain of the contact law.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from . import _stream
from . import _trajectory_checks as _checks
from ._extras import require
from ._readable import readable
from ._result import Result
from ._status import Status
from ._stream import STATUS_CODES, Streamed
from .errors import CoulombError, InternalError, ProblemFormatError

if TYPE_CHECKING:
    from .model import Scene

__all__ = ["Streamed", "Trajectory", "TrajectoryCheckError"]


#: the arrays a trajectory file of the first version may lack.
_LATER_ARRAYS = ("error_q", "error_q_floor", "load_power")


def _load_power(scene: Scene | None, v: np.ndarray) -> np.ndarray:
    """``f . v`` per state of the constant loads ``m g + F`` of a scene's bodies (on their
    translational velocities); zeros without a scene."""
    if scene is None or v.ndim != 2:
        return np.zeros(len(v))
    f = np.zeros(v.shape[1])
    g = np.asarray(scene.gravity, dtype=np.float64)
    for b, (_, sv) in zip(scene.bodies, scene.layout(), strict=True):
        load = b.mass * g
        if b.force is not None:
            load = load + np.asarray(b.force, dtype=np.float64)
        f[sv.start:sv.start + scene.dim] = load
    return np.asarray(v @ f, dtype=np.float64)




#: the Status of each code of STATUS_CODES, and whether it counts as a solved step.
_STATUS_BY_CODE = np.empty(len(STATUS_CODES), dtype=object)
for _name, _code in STATUS_CODES.items():
    _STATUS_BY_CODE[_code] = Status(_name)
_SUCCEEDED = np.array([s in (Status.SOLVED, Status.NO_CONTACT) for s in _STATUS_BY_CODE])


class TrajectoryCheckError(CoulombError, AssertionError):
    """A trajectory failed :meth:`Trajectory.check` with ``strict=True``."""


#: the arrays the stepper records, by the name the core gives them (its ``status``, ``error``,
#: ``scaled_error``, ``error_q`` and ``error_q_floor`` are a step's, renamed ``solver_*`` here).
_CORE_NAMES = frozenset({
    "dim", "t", "q", "v", "kinetic_energy", "potential_energy", "load_power", "min_gap",
    "negative_gaps", "active", "status", "error", "scaled_error", "error_q", "error_q_floor",
    "iterations",
    "momentum_residual", "min_normal_impulse", "cone_violation", "complementarity", "resumed",
    "fallback", "projection", "contact_step", "contact_id", "contact_impulse",
    "contact_velocity", "contact_approach", "contact_gap", "contact_closed", "stopped",
    "solve_time",
})


class Trajectory:
    """States, impulses and per-step checks of a simulation.

    Made by :meth:`coulomb.Scene.simulate` and :meth:`coulomb.Model.simulate`; every array is a
    NumPy array. ``N`` is the number of recorded rows of steps (of the ``ceil(t_end / h)``
    steps, every ``record_every``-th and the last; fewer if the run stopped), the states are
    the ``N + 1`` instants ``t_0 .. t_N``, and the contact records have one row per active
    contact per recorded step.

    Attributes
    ----------
    success : bool
        Every step ran and every contact solve succeeded (``status == "completed"``).
    status : Status
        ``Status.COMPLETED``, ``Status.SOLVER_FAILURES`` (some contact solve missed its
        tolerance) or ``Status.STOPPED`` (the run stopped early); equal to its string.
    message : str
        One line for a person.
    t : ndarray, shape (N + 1,)
        Times (s).
    q : ndarray, shape (N + 1, nq)
        Coordinates of every body in the order added (:meth:`body` slices one out): a
        particle's position, a planar body's ``(x, y, theta)``, a spatial body's position and
        unit quaternion ``(w, x, y, z)``.
    v : ndarray, shape (N + 1, nv)
        Velocities: a planar body's ``(vx, vy, omega)``, a spatial body's velocity and angular
        velocity (world frame).
    kinetic_energy : ndarray, shape (N + 1,)
        ``T`` (J).
    potential_energy : ndarray, shape (N + 1,)
        ``V`` of gravity and the constant forces, ``-sum (m g + F) . x`` (J).
    total_energy : ndarray, shape (N + 1,)
        ``T + V`` (J).
    load_power : ndarray, shape (N + 1,)
        ``f . v`` of those constant loads (W; for a :class:`~coulomb.Model`, of its
        ``force(q, v, t)``).
    min_gap : ndarray, shape (N + 1,)
        The smallest gap over every candidate contact (m).
    negative_gaps : ndarray of int, shape (N + 1,)
        How many candidates are below ``-gap_tolerance``.
    active : ndarray of int, shape (N,)
        Contacts that carried unknowns in step k (from ``t_k`` to ``t_{k+1}``).
    solver_status : ndarray of Status, shape (N,)
        The contact solver's verdict on step k; ``Status.NO_CONTACT`` when none was active.
    solver_error : ndarray, shape (N,)
        The literature's natural-map residual of step k's contact solve.
    solver_scaled_error : ndarray, shape (N,)
        The unit-consistent residual, half of the verdict (see :mod:`coulomb.contact`): a
        solved step has it at most ``tol``.
    solver_error_q : ndarray, shape (N,)
        The literature's residual relative to ``||q||``, the verdict's other half: a solved
        step has it at most ``max(tol, 1e-9, solver_error_q_floor)``.
    solver_error_q_floor : ndarray, shape (N,)
        The rounding level of ``solver_error_q`` at the step's answer.
    iterations : ndarray of int, shape (N,)
        Sweeps, Newton steps or pivots of step k's solve (the most over its islands).
    momentum_residual : ndarray, shape (N,)
        ``||M (v_{k+1} - v_free) - G P||`` over ``max(||G P||, ||M v_free||, ||M v_{k+1}||)``.
    min_normal_impulse : ndarray, shape (N,)
        ``min P_n`` over the step's contacts (N s).
    cone_violation : ndarray, shape (N,)
        ``max(||P_t|| - mu P_n, 0)`` (N s).
    complementarity : ndarray, shape (N,)
        ``max |P_n (J_n v_{k+1} + e v_n^-)|``, with the gap term ``g / h`` for an open contact
        (N m).
    resumed : ndarray of bool, shape (N,)
        A closed contact took its restitution from the approach velocity of the step that
        closed it.
    fallback : ndarray of bool, shape (N,)
        The step's solver missed its tolerance and the fallback decided the step: its
        answer was used, or judged at the fallback's ``max(tol, 1e-9)`` (see ``fallback`` of
        ``Scene.simulate``).
    projection : ndarray, shape (N,)
        The largest coordinate change of the drift projection (0 without it).
    contact_step : ndarray of int, shape (n_records,)
        The step (row of the step arrays) of each contact record.
    contact_id : ndarray of int, shape (n_records,)
        The contact's id, stable over steps (the candidate pair of features).
    contact_impulse : ndarray, shape (n_records, dim)
        The impulse, normal first (N s).
    contact_velocity : ndarray, shape (n_records, dim)
        ``J v_{k+1}`` in the contact frame (m/s).
    contact_approach : ndarray, shape (n_records,)
        The approach velocity the impact law used (m/s).
    contact_gap : ndarray, shape (n_records,)
        The gap at ``t_k`` (m).
    contact_closed : ndarray of bool, shape (n_records,)
        Whether the contact was closed (restitution applied) rather than closing.
    dim : int
        2 (planar) or 3 (spatial).
    h : float
        The time step (s).
    solver : str
        ``"nsgs"`` or ``"lemke"``.
    tol : float
        The contact solver's tolerance.
    gap_tolerance : float
        The gap (m) at or below which a contact is closed.
    record_every : int
        Steps per recorded row (the checks of a row are the worst over its steps).
    stopped : str or None
        Why the run stopped early, or None.
    solve_time : float
        Seconds spent in the stepper (NaN for a :class:`~coulomb.Model`, stepped in Python).
    scene : Scene or None
        The simulated scene (None for a :class:`~coulomb.Model`).
    """

    __slots__ = (
        "active",
        "complementarity",
        "cone_violation",
        "contact_approach",
        "contact_closed",
        "contact_gap",
        "contact_id",
        "contact_impulse",
        "contact_step",
        "contact_velocity",
        "dim",
        "fallback",
        "gap_tolerance",
        "h",
        "iterations",
        "kinetic_energy",
        "load_power",
        "message",
        "min_gap",
        "min_normal_impulse",
        "momentum_residual",
        "negative_gaps",
        "potential_energy",
        "projection",
        "q",
        "record_every",
        "resumed",
        "scene",
        "solve_time",
        "solver",
        "solver_error",
        "solver_error_q",
        "solver_error_q_floor",
        "solver_scaled_error",
        "solver_status",
        "status",
        "stopped",
        "success",
        "t",
        "tol",
        "total_energy",
        "v",
    )

    success: bool
    status: Status
    message: str
    t: NDArray[np.float64]
    q: NDArray[np.float64]
    v: NDArray[np.float64]
    kinetic_energy: NDArray[np.float64]
    potential_energy: NDArray[np.float64]
    total_energy: NDArray[np.float64]
    load_power: NDArray[np.float64]
    min_gap: NDArray[np.float64]
    negative_gaps: NDArray[np.int64]
    active: NDArray[np.int64]
    solver_status: NDArray[np.object_]
    solver_error: NDArray[np.float64]
    solver_scaled_error: NDArray[np.float64]
    solver_error_q: NDArray[np.float64]
    solver_error_q_floor: NDArray[np.float64]
    iterations: NDArray[np.int64]
    momentum_residual: NDArray[np.float64]
    min_normal_impulse: NDArray[np.float64]
    cone_violation: NDArray[np.float64]
    complementarity: NDArray[np.float64]
    resumed: NDArray[np.bool_]
    fallback: NDArray[np.bool_]
    projection: NDArray[np.float64]
    contact_step: NDArray[np.int64]
    contact_id: NDArray[np.int64]
    contact_impulse: NDArray[np.float64]
    contact_velocity: NDArray[np.float64]
    contact_approach: NDArray[np.float64]
    contact_gap: NDArray[np.float64]
    contact_closed: NDArray[np.bool_]
    dim: int
    h: float
    solver: str
    tol: float
    gap_tolerance: float
    record_every: int
    stopped: str | None
    solve_time: float
    scene: Scene | None

    def __init__(self) -> None:
        raise TypeError("a Trajectory is made by Scene.simulate or Model.simulate")

    @classmethod
    def _from_core(cls, raw: Mapping[str, Any], scene: Scene | None, h: float, solver: str,
                   gap_tolerance: float, tol: float, record_every: int = 1) -> Trajectory:
        """The trajectory of the arrays a stepper recorded (``raw``, by the core's names)."""
        unknown = set(raw) - _CORE_NAMES
        if unknown:
            raise InternalError(f"the stepper recorded unknown arrays {sorted(unknown)}")
        tr = object.__new__(cls)
        for name in ("t", "q", "v", "kinetic_energy", "potential_energy", "min_gap",
                     "negative_gaps", "active", "iterations", "momentum_residual",
                     "min_normal_impulse", "cone_violation", "complementarity", "resumed",
                     "fallback", "contact_step", "contact_id", "contact_impulse",
                     "contact_velocity", "contact_approach", "contact_gap", "contact_closed"):
            setattr(tr, name, np.asarray(raw[name]))
        n = len(tr.t) - 1
        tr.dim = int(raw["dim"])
        tr.stopped = raw["stopped"]
        tr.solve_time = float(raw["solve_time"])
        tr.scene = scene
        tr.h, tr.solver, tr.tol = float(h), str(solver), float(tol)
        tr.gap_tolerance, tr.record_every = float(gap_tolerance), int(record_every)
        tr.total_energy = tr.kinetic_energy + tr.potential_energy
        tr.load_power = (np.asarray(raw["load_power"]) if "load_power" in raw
                         else _load_power(scene, tr.v))
        tr.projection = (np.asarray(raw["projection"]) if "projection" in raw
                         else np.zeros(len(tr.active)))
        # each step's status by its code (the core's and the files' STATUS_CODES)
        codes = np.asarray(raw["status"]).astype(np.intp, copy=False)
        tr.solver_status = _STATUS_BY_CODE[codes]
        tr.solver_error = np.asarray(raw["error"])
        tr.solver_scaled_error = np.asarray(raw["scaled_error"])
        # files streamed before error_q joined the verdict have neither column
        n_steps = len(tr.solver_scaled_error)
        tr.solver_error_q = (np.asarray(raw["error_q"]) if "error_q" in raw
                             else np.zeros(n_steps))
        tr.solver_error_q_floor = (np.asarray(raw["error_q_floor"]) if "error_q_floor" in raw
                                   else np.zeros(n_steps))
        failed = int(np.count_nonzero(~_SUCCEEDED[codes]))
        if tr.stopped is not None:
            tr.status, tr.message = Status.STOPPED, f"stopped early: {tr.stopped}"
        elif failed:
            tr.status = Status.SOLVER_FAILURES
            tr.message = f"{n} steps; {failed} contact solves missed their tolerance"
        else:
            tr.status = Status.COMPLETED
            tr.message = f"{n} steps, every contact solve solved"
        tr.success = tr.status == Status.COMPLETED
        return tr

    @classmethod
    def load(cls, path: str | os.PathLike[str], scene: Scene | None = None) -> Trajectory:
        """Reads a trajectory written by :meth:`Scene.stream <coulomb.model.Scene.stream>`
        (h5py, the optional extra ``coulomb[hdf5]``) into memory; ``scene`` (the one streamed)
        gives :meth:`body` (and the load power of a file written before it was stored)."""
        require("h5py", extra="hdf5", what="Trajectory.load")
        import h5py

        with h5py.File(Path(path), "r") as f:
            if f.attrs.get("format") != _stream.FORMAT:
                raise ProblemFormatError(f"{str(path)!r} is not a coulomb trajectory file")
            a = f.attrs
            rows = {"states": int(a.get("states", 0)), "steps": int(a.get("steps", 0)),
                    "contacts": int(a.get("contacts", 0))}
            if rows["states"] == 0:
                raise ProblemFormatError(f"{str(path)!r} holds no states (its run stopped "
                                         "before the first chunk was written)")
            # error_q, error_q_floor and load_power joined the file after its first version
            # (an older file's load power is formed from ``scene``)
            raw: dict[str, Any] = {name: f[name][:rows[_stream.ROWS[name]]]
                                   for name in _stream.ARRAYS
                                   if name in f or name not in _LATER_ARRAYS}
            codes = np.asarray(raw["status"])
            if codes.size and (codes.dtype.kind not in "iu" or codes.min() < 0
                               or codes.max() >= len(_STATUS_BY_CODE)):
                raise ProblemFormatError(
                    f"{str(path)!r}: step status codes must be integers in "
                    f"[0, {len(_STATUS_BY_CODE)}), got {codes.dtype} from {codes.min()} to "
                    f"{codes.max()}")
            raw["dim"] = int(a["dim"])
            stopped = str(a.get("stopped", ""))
            if not bool(a.get("complete", False)):
                stopped = stopped or "the run did not finish writing the file (interrupted)"
            raw["stopped"] = stopped or None
            raw["solve_time"] = float(a.get("solve_time", 0.0))
            return cls._from_core(raw, scene=scene, h=float(a["h"]), solver=str(a["solver"]),
                                  gap_tolerance=float(a["gap_tolerance"]), tol=float(a["tol"]),
                                  record_every=int(a["record_every"]))

    # -- access ----------------------------------------------------------------------------

    def body(self, index: int) -> Result:
        """Coordinates ``q`` and velocities ``v`` of one body (in the order added)."""
        if self.scene is None:
            raise TypeError("body() needs a Scene; a generalized-coordinate Model has none")
        sq, sv = self.scene.layout()[index]
        return Result(q=self.q[:, sq], v=self.v[:, sv])

    def normal_impulse_per_step(self) -> np.ndarray:
        """The sum of the normal impulses of every step (``N`` entries, N s)."""
        out = np.zeros(len(self.t) - 1)
        np.add.at(out, self.contact_step, self.contact_impulse[:, 0])
        return out

    def __repr__(self) -> str:
        n = len(self.t) - 1
        statuses, counts = np.unique(self.solver_status, return_counts=True)
        st = ", ".join(f"{s}: {c}" for s, c in zip(statuses, counts, strict=True))
        worst = _checks.worst(self)
        lines = [
            f"Trajectory({n} steps of h = {self.h:.3g} s to t = {self.t[-1]:.6g} s, "
            f"solver {self.solver!r}",
            f"  bodies: {len(self.scene.bodies) if self.scene else 'generalized model'}, "
            f"q: {self.q.shape}, v: {self.v.shape}",
            f"  contact records: {len(self.contact_step)}, steps by status: {{{st}}}",
            f"  min gap: {np.min(self.min_gap):.3e} m, energy: "
            f"{self.total_energy[0]:.6g} J -> {self.total_energy[-1]:.6g} J",
            "  worst: " + ", ".join(f"{k} {readable(v)}" for k, v in worst.items()),
        ]
        if self.stopped is not None:
            lines.append(f"  STOPPED: {self.stopped}")
        return "\n".join(lines) + ")"

    __str__ = __repr__

    # -- checks ----------------------------------------------------------------------------

    def step_energy(self) -> np.ndarray:
        """The energy the impulse step keeps, ``E_h = T + V + (h/2) f . v`` per state (J; see
        the module documentation)."""
        return self.total_energy + 0.5 * self.h * self.load_power

    def energy_gain(self) -> np.ndarray:
        """Per step, how much ``T + V`` rose beyond the loads' O(h) work of the step,
        ``(h/2) |f . (v_{k+1} - v_k)|`` (J, negative when it fell): the difference between
        ``T + V`` and the step's energy ``E_h`` (module documentation), so that a step whose
        ``E_h`` does not rise passes, and so does a step whose ``E_h`` rises by less than
        ``h f . (v_{k+1} - v_k)`` when that is positive (the loads' share of a sticking or
        pivoting contact whose Jacobian turns with the step). A step that gives back a
        rebound (``resumed``) is judged across it and the step that closed the contact (the
        landing step takes the approach energy, the rebound step returns it); in a run of
        such steps (a rebound step that lands another contact, or a resting contact whose gap
        term pushes every other step) each is judged against the highest energy since the
        run's landing step began, so a rebound already judged is not counted again as a gain
        of the next step."""
        return _checks.energy_gain(self)

    def check(
        self,
        strict: bool = False,
        *,
        momentum_tol: float = 1e-10,
        energy_tol: float = 1e-9,
        gap_tol: float | None = None,
    ) -> Result:
        """Every violation of the per-step checks, as a summary.

        The contact law of each step (normal impulses ``>= 0``, friction cone,
        complementarity, sticking or sliding) is judged by the rule and the measure of the
        step's own verdict: the step's ``solver_scaled_error`` (the unit-consistent residual of
        :mod:`coulomb.contact`, relative to the step's impulses) at most the solver's ``tol``
        (``max(tol, 1e-9)`` for a step the fallback decided) and its
        ``solver_error_q`` at most ``max(tol, 1e-9, solver_error_q_floor)`` (a step holds the
        literature's half at 1e-9 when its ``tol`` is tighter: on a stack ``error_q`` divides by
        a ``||q||`` far below the terms the bottom impulses cancel). The raw figures
        (``min_normal_impulse``, ``cone_violation``, ``complementarity``) are reported in
        absolute units and not judged again with another scale, so the check and the solver
        cannot disagree. For the polyhedral cone in 3D (``solver="lemke"``) the verdict is
        the polygon's LCP and the exact-cone residual measures the facet error: there only
        the status is judged.

        Other checks: no NaN or infinity, every contact solve succeeded, momentum balance
        (``momentum_tol``, relative), no penetration beyond ``gap_tol`` (m; default the
        simulation's ``gap_tolerance``) and no step raising ``T + V`` by more than the loads'
        O(h) work ``(h/2) |f . (v_{k+1} - v_k)|`` (:meth:`energy_gain`) beyond ``energy_tol``
        times the largest ``|T| + |V| + |(h/2) f . v|`` of the trajectory. The step's energy
        ``E_h = T + V + (h/2) f . v`` (:meth:`step_energy`) is what the impulse step keeps in
        flight and at impacts with ``e <= 1``, so elastic bounces under gravity pass at any h,
        while energy put in by a force, by the velocity bias of ``drift="velocity_bias"`` or
        by the contact law is flagged. The plain step's impact on a turning normal (a
        rotating corner, oblique spheres) rebounds with the approach velocity of the landing
        step's start, which along the step changes at the gap's second derivative ``g''``: it
        gains up to ``h m_eff |v_n^-| |g''|`` per impact (two spheres: ``g'' = |v_t|^2 / d``),
        which is flagged too; ``locate_impacts=True`` removes it for isolated impacts.
        Newton's law with friction is such a law: an impact that sticks can gain energy
        (Kane and Levinson's rod: a rod at 45 degrees striking at ``(0.6, -1)`` m/s with
        ``e = 1`` gains 0.1125 J; Stewart 2000), and check() reports it as an energy gain;
        ``restitution="poisson"`` never gains for one frictional contact. With
        ``strict=True`` a violation raises :class:`TrajectoryCheckError`.
        """
        out = _checks.check(self, momentum_tol=momentum_tol, energy_tol=energy_tol,
                            gap_tol=gap_tol)
        if strict and not out.ok:
            raise TrajectoryCheckError("; ".join(out.violations))
        return out

    # -- plots -----------------------------------------------------------------------------

    def plot(self, axes: Any = None) -> Any:
        """Coordinates, energy and normal impulses against time (needs matplotlib, the
        ``plot`` extra). Each coordinate is labelled by body and name with its unit
        (``"ball y [m]"``, ``"box theta [rad]"``; ``q[i]`` for a generalized model), in a legend
        up to 21 coordinates. Returns the figure."""
        require("matplotlib", extra="plot", what="Trajectory.plot")
        import matplotlib.pyplot as plt

        from ._plot import coordinate_labels

        if axes is None:
            fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 8))
        else:
            fig = axes[0].figure
        t = self.t
        labels = coordinate_labels(self.scene, self.q.shape[1])
        for column, label in zip(self.q.T, labels, strict=True):
            axes[0].plot(t, column, label=label)
        if self.scene is None:
            axes[0].set_ylabel("q (generalized)")
        else:
            units = sorted({lb[lb.rfind("[") + 1:-1] for lb in labels})
            axes[0].set_ylabel(f"q [{', '.join(units)}]")
        if len(labels) <= 21:
            axes[0].legend(fontsize=7, ncol=1 + (len(labels) - 1) // 7, loc="best")
        axes[1].plot(t, self.kinetic_energy, label="kinetic")
        axes[1].plot(t, self.potential_energy, label="potential")
        axes[1].plot(t, self.total_energy, label="total")
        axes[1].set_ylabel("energy [J]")
        axes[1].legend(fontsize=7)
        axes[2].step(t[:-1], self.normal_impulse_per_step(), where="post",
                     label="sum over contacts")
        axes[2].set_ylabel("normal impulse per step [N s]")
        axes[2].set_xlabel("t [s]")
        axes[2].legend(fontsize=7)
        return fig

    def animate(self, path: str | Path | None = None, **options: Any) -> Any:
        """The scene's bodies and shapes moving over time, in 2D or 3D (needs matplotlib, the
        ``plot`` extra; see :mod:`coulomb._animate` for what each shape looks like).

        With ``path`` it writes a ``.gif`` (Pillow, which matplotlib brings), ``.mp4``
        (needs ffmpeg; :class:`~coulomb._animate.WriterUnavailableError` otherwise, before any
        work) or ``.html`` file and returns the path; without, it returns a
        :class:`~coulomb._animate.SceneAnimation`, which Jupyter shows inline as a player
        (``.animation`` is the matplotlib ``FuncAnimation``, ``.rgba(k)`` frame k's pixels).

        Options: ``fps`` (default 25), ``every`` (draw every k-th state; default real time at
        ``fps``), ``t_range=(t0, t1)`` (s), ``limits`` (``dim`` pairs (low, high) in m;
        default every shape over the frames, with a margin), ``title`` (True: ``"t = ... s"``;
        a format string with ``{t}``; False: none), ``figsize`` (inches), ``dpi``.
        A generalized-coordinate :class:`~coulomb.Model` has no geometry: TypeError (plot its
        coordinates with :meth:`plot`).
        """
        from ._animate import animate

        return animate(self, path, **options)
