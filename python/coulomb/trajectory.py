r"""The result of :meth:`coulomb.Scene.simulate`: states, impulses and the seed's per-step
checks ("Time-step accuracy and validation").

States (``N + 1`` rows, times ``t_0 .. t_N``): ``t``, ``q``, ``v``, ``kinetic_energy``,
``potential_energy`` (of gravity and the constant forces, ``-sum (m g + F) . x``),
``total_energy``, ``load_power`` (``f . v`` of those constant loads, W; for a
:class:`~coulomb.Model`, of its ``force(q, v, t)``), ``min_gap`` (over every candidate
contact) and ``negative_gaps`` (how many candidates are below ``-gap_tolerance``).

The energy the impulse step keeps is not ``T + V`` but ``E_h = T + V + (h/2) f . v``: with
``v_{k+1} = v_k + h M^{-1} f + M^{-1} G P`` and ``x_{k+1} = x_k + h v_{k+1}``, the identity
``T(v_{k+1}) - T(v_k) = (v_k + v_{k+1})/2 . (h f + G P)`` for a constant M gives

``E_h(k+1) - E_h(k) = (v_k + v_{k+1})/2 . G P``,

the work of the contact impulses at the mean velocity (Moreau's energy balance), which is
``<= 0`` for an impact with ``e <= 1`` and for Coulomb friction that dissipates. ``T + V``
itself moves by ``-(h/2) f . (v_{k+1} - v_k)`` more: the loads' O(h) work over the step, about
``m g h |v_n|`` at each bounce under gravity (``T + V`` rises when the ball leaves the floor
and falls back in flight), which is the integrator's and not a gain of the contact law.

Steps (``N`` rows, step k from ``t_k`` to ``t_{k+1}``): ``active`` contacts, the contact
solver's ``solver_status`` (``"no_contact"`` when none was active), ``solver_error`` (the
literature's natural-map residual), ``solver_scaled_error`` (the unit-consistent measure the
verdict is taken on, see :mod:`coulomb.contact`: a step is solved when it is at most ``tol``)
and ``iterations``, ``momentum_residual``
(``||M (v_{k+1} - v_free) - G P||`` over ``max(||G P||, ||M v_free||, ||M v_{k+1}||)``),
``min_normal_impulse``, ``cone_violation``
(``max(||P_t|| - mu P_n, 0)``), ``complementarity`` (``max |P_n (J_n v_{k+1} + e v_n^-)|``,
or with the gap term ``g / h`` for an open contact) and ``resumed`` (a closed contact took its
restitution from the approach velocity of the step that closed it) and ``fallback`` (NSGS missed
its tolerance and the polyhedral Lemke's better answer was used), and ``projection`` (the
largest coordinate change of the drift projection, 0 without it).

Contacts (one row per active contact per step): ``contact_step``, ``contact_id`` (stable over
steps: the candidate pair of features), ``contact_impulse`` (normal first, N s),
``contact_velocity`` (``J v_{k+1}`` in the contact frame), ``contact_approach``,
``contact_gap`` and ``contact_closed``.

Like every coulomb result it has ``success``, ``status`` (``"completed"``,
``"solver_failures"`` or ``"stopped"``) and a one-line ``message``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._extras import require
from ._result import Result
from .errors import CoulombError

if TYPE_CHECKING:
    from .model import Scene

__all__ = ["Trajectory", "TrajectoryCheckError"]


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


class TrajectoryCheckError(CoulombError, AssertionError):
    """A trajectory failed :meth:`Trajectory.check` with ``strict=True``."""


class Trajectory(Result):
    """States, impulses and per-step checks of a simulation (see the module documentation)."""

    @classmethod
    def _from_core(cls, raw: dict[str, Any], scene: Scene | None, h: float, solver: str,
                   gap_tolerance: float, tol: float) -> Trajectory:
        tr = cls(raw)
        tr["gap_tolerance"] = gap_tolerance
        tr["tol"] = tol
        tr["total_energy"] = tr["kinetic_energy"] + tr["potential_energy"]
        if "load_power" not in tr:
            tr["load_power"] = _load_power(scene, tr["v"])
        tr["h"] = h
        tr["solver"] = solver
        tr["solver_status"] = np.asarray(tr.pop("status"), dtype=object)
        tr["solver_error"] = tr.pop("error")
        tr["solver_scaled_error"] = tr.pop("scaled_error")
        failed = int(np.sum([s not in ("solved", "no_contact") for s in tr["solver_status"]]))
        n = len(tr["t"]) - 1
        if tr["stopped"] is not None:
            tr["status"], tr["message"] = "stopped", f"stopped early: {tr['stopped']}"
        elif failed:
            tr["status"] = "solver_failures"
            tr["message"] = f"{n} steps; {failed} contact solves missed their tolerance"
        else:
            tr["status"], tr["message"] = "completed", f"{n} steps, every contact solve solved"
        tr["success"] = tr["status"] == "completed"
        object.__setattr__(tr, "_scene", scene)
        return tr

    # -- access ----------------------------------------------------------------------------

    def body(self, index: int) -> Result:
        """Coordinates ``q`` and velocities ``v`` of one body (in the order added)."""
        if self._scene is None:
            raise TypeError("body() needs a Scene; a generalized-coordinate Model has none")
        sq, sv = self._scene.layout()[index]
        return Result(q=self["q"][:, sq], v=self["v"][:, sv])

    def normal_impulse_per_step(self) -> np.ndarray:
        """The sum of the normal impulses of every step (``N`` entries, N s)."""
        out = np.zeros(len(self["t"]) - 1)
        np.add.at(out, self["contact_step"], self["contact_impulse"][:, 0])
        return out

    def __repr__(self) -> str:
        n = len(self["t"]) - 1
        statuses, counts = np.unique(self["solver_status"], return_counts=True)
        st = ", ".join(f"{s}: {c}" for s, c in zip(statuses, counts, strict=True))
        worst = self._worst()
        lines = [
            f"Trajectory({n} steps of h = {self['h']:.3g} s to t = {self['t'][-1]:.6g} s, "
            f"solver {self['solver']!r}",
            f"  bodies: {len(self._scene.bodies) if self._scene else 'generalized model'}, "
            f"q: {self['q'].shape}, v: {self['v'].shape}",
            f"  contact records: {len(self['contact_step'])}, steps by status: {{{st}}}",
            f"  min gap: {np.min(self['min_gap']):.3e} m, energy: "
            f"{self['total_energy'][0]:.6g} J -> {self['total_energy'][-1]:.6g} J",
            "  worst: " + ", ".join(f"{k} {v:.2e}" for k, v in worst.items()),
        ]
        if self["stopped"] is not None:
            lines.append(f"  STOPPED: {self['stopped']}")
        return "\n".join(lines) + ")"

    __str__ = __repr__

    # -- checks ----------------------------------------------------------------------------

    def _worst(self) -> dict[str, float]:
        def mx(a: np.ndarray) -> float:
            return float(np.max(a)) if len(a) else 0.0

        return {
            "momentum_residual": mx(self["momentum_residual"]),
            "solver_error": mx(self["solver_error"]),
            "solver_scaled_error": mx(self["solver_scaled_error"]),
            "cone_violation": mx(self["cone_violation"]),
            "complementarity": mx(self["complementarity"]),
            "energy_gain": float(np.max(self.energy_gain(), initial=0.0)),
        }

    def step_energy(self) -> np.ndarray:
        """The energy the impulse step keeps, ``E_h = T + V + (h/2) f . v`` per state (J; see
        the module documentation)."""
        return self["total_energy"] + 0.5 * self["h"] * self["load_power"]

    def energy_gain(self) -> np.ndarray:
        """Per step, how much ``T + V`` rose beyond the loads' O(h) work of the step,
        ``(h/2) |f . (v_{k+1} - v_k)|`` (J, negative when it fell): the difference between
        ``T + V`` and the step's energy ``E_h`` (module documentation), so that a step whose
        ``E_h`` does not rise passes, and so does a step whose ``E_h`` rises by less than
        ``h f . (v_{k+1} - v_k)`` when that is positive (the loads' share of a sticking or
        pivoting contact whose Jacobian turns with the step). A step that gives back a
        rebound (``resumed``) is judged across it and the step that closed the contact (the
        landing step takes the approach energy, the rebound step returns it)."""
        e, w = self["total_energy"], 0.5 * self["h"] * self["load_power"]
        gain = np.diff(e) - np.abs(np.diff(w))
        for k in np.flatnonzero(self["resumed"]):
            if k >= 1:
                gain[k] = e[k + 1] - e[k - 1] - abs(w[k + 1] - w[k - 1])
        return gain

    def _energy_tolerance(self, energy_tol: float) -> float:
        """``energy_tol`` times the trajectory's energy scale, the largest
        ``|T| + |V| + |(h/2) f . v|`` over its states (the terms ``E_h`` is summed from, so
        the rounding of ``E_h`` and of the contact solves' residuals is in proportion):
        unit-consistent, with no absolute floor."""
        t, p = self["kinetic_energy"], self["potential_energy"]
        w = 0.5 * self["h"] * self["load_power"]
        if len(t) == 0:
            return 0.0
        return energy_tol * float(np.max(np.abs(t) + np.abs(p) + np.abs(w)))

    def check(
        self,
        strict: bool = False,
        *,
        momentum_tol: float = 1e-10,
        energy_tol: float = 1e-9,
        gap_tol: float | None = None,
    ) -> Result:
        """Every violation of the seed's checks, as a summary.

        The contact law of each step (normal impulses ``>= 0``, friction cone,
        complementarity, sticking or sliding) is judged by the rule and the measure of the
        step's own verdict: the step's ``solver_scaled_error`` (the unit-consistent residual of
        :mod:`coulomb.contact`, relative to the step's impulses) at most the solver's ``tol``
        (``max(tol, 1e-9)`` for a step decided by the Lemke fallback). The raw figures
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
        v: list[str] = []
        if self["stopped"] is not None:
            v.append(f"stopped early: {self['stopped']}")
        for name in ("q", "v", "contact_impulse"):
            if not np.all(np.isfinite(self[name])):
                v.append(f"{name} has non-finite values")
        status = self["solver_status"]
        bad = [(k, s) for k, s in enumerate(status) if s not in ("solved", "no_contact")]
        if bad:
            k, s = bad[0]
            v.append(f"{len(bad)} contact solves did not succeed (first: step {k}, {s}, "
                     f"scaled_error {self['solver_scaled_error'][k]:.2e})")
        # the verdict's own rule on the recorded measure (see the docstring)
        exact = self["solver"] != "lemke" or self._planar()
        if exact:
            tol = np.where(self["fallback"], max(self["tol"], 1e-9), self["tol"])
            se = self["solver_scaled_error"]
            solved = np.array([s == "solved" for s in status], dtype=bool)
            wrong = np.flatnonzero(solved & ~(se <= tol))
            if len(wrong):
                k = int(wrong[0])
                v.append(f"{len(wrong)} steps reported solved whose scaled_error exceeds tol "
                         f"(first: step {k}, {se[k]:.2e} > {tol[k]:.1e})")
        res = self["momentum_residual"]
        if np.any(res > momentum_tol):
            v.append(f"momentum residual up to {res.max():.2e} > {momentum_tol:.1e}")
        if gap_tol is None:
            gap_tol = self["gap_tolerance"]
        gaps = self["min_gap"]
        if np.any(gaps < -gap_tol):
            k = int(np.argmin(gaps))
            v.append(f"penetration: min gap {gaps[k]:.3e} m at t = {self['t'][k]:.6g} s "
                     f"({int(np.sum(gaps < -gap_tol))} states)")
        etol = self._energy_tolerance(energy_tol)
        gain = self.energy_gain()
        if np.any(gain > etol):
            k = int(np.argmax(gain))
            v.append(f"energy gained in {int(np.sum(gain > etol))} steps, up to "
                     f"{gain[k]:.3e} J (step {k}, t = {self['t'][k]:.6g} s)")
        out = Result(ok=not v, violations=v, **self._worst())
        if strict and v:
            raise TrajectoryCheckError("; ".join(v))
        return out

    def _planar(self) -> bool:
        """Whether the contacts are planar (dim 2), where the polyhedral cone is exact."""
        return int(self.get("dim", 0)) == 2

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
        t = self["t"]
        labels = coordinate_labels(self._scene, self["q"].shape[1])
        for column, label in zip(self["q"].T, labels, strict=True):
            axes[0].plot(t, column, label=label)
        if self._scene is None:
            axes[0].set_ylabel("q (generalized)")
        else:
            units = sorted({lb[lb.rfind("[") + 1:-1] for lb in labels})
            axes[0].set_ylabel(f"q [{', '.join(units)}]")
        if len(labels) <= 21:
            axes[0].legend(fontsize=7, ncol=1 + (len(labels) - 1) // 7, loc="best")
        axes[1].plot(t, self["kinetic_energy"], label="kinetic")
        axes[1].plot(t, self["potential_energy"], label="potential")
        axes[1].plot(t, self["total_energy"], label="total")
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
