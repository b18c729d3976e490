"""Streaming a scene's trajectory to an HDF5 file (:meth:`coulomb.model.Scene.stream`).

The stepper hands its records out in chunks of at most ``chunk`` kept states; each chunk is
appended to resizable datasets and dropped, so the memory of a run does not grow with its
length. The file holds one dataset per array of :class:`~coulomb.trajectory.Trajectory`, by the
same names (``t``, ``q``, ``v``, ``kinetic_energy``, ``potential_energy``, ``load_power``,
``min_gap``, ``negative_gaps``, the step checks ``active``, ``status``, ``error``, ``scaled_error``,
``error_q``, ``error_q_floor``, ``iterations``, ``momentum_residual``, ``min_normal_impulse``,
``cone_violation``, ``complementarity``, ``resumed``, ``fallback``, ``projection``, and the
contact records ``contact_step``, ``contact_id``, ``contact_impulse``, ``contact_velocity``,
``contact_approach``, ``contact_gap``, ``contact_closed``; ``status`` an HDF5 enum of the
status names, :data:`STATUS_CODES`), and attributes ``format`` (``"coulomb-trajectory"``),
``version``, ``dim``, ``h``, ``solver``, ``tol``, ``gap_tolerance``, ``record_every``,
``stopped`` (empty when every step ran), ``solve_time``, ``complete`` (false until the run
ended, so a file of a run cut short says so) and ``states``, ``steps``, ``contacts`` (the rows
of the whole chunks written). The datasets are stored in chunks of about 64 KiB, which keeps
HDF5's own memory flat too (a variable-length string per status made it grow with the run).
:meth:`Trajectory.load <coulomb.trajectory.Trajectory.load>` reads it back.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._status import Status
from .errors import InvalidParameterError

if TYPE_CHECKING:
    from .model import Scene
    from .trajectory import Trajectory

FORMAT = "coulomb-trajectory"
VERSION = 1

#: the codes of the step statuses, as the core returns them and the file stores them (an HDF5
#: enum, ``status``).
STATUS_CODES = {"no_contact": 0, "solved": 1, "iteration_limit": 2, "numerical_failure": 3}

#: the per-state, per-step and per-contact arrays, in the core's names.
ARRAYS = (
    "t", "q", "v", "kinetic_energy", "potential_energy", "load_power", "min_gap", "negative_gaps",
    "active",
    "status", "error", "scaled_error", "error_q", "error_q_floor", "iterations",
    "momentum_residual", "min_normal_impulse", "cone_violation", "complementarity", "resumed",
    "fallback", "projection", "contact_step", "contact_id", "contact_impulse", "contact_velocity",
    "contact_approach", "contact_gap", "contact_closed",
)

#: which row count of the file (its attributes ``states``, ``steps``, ``contacts``) each array
#: has.
ROWS = {name: ("states" if name in ("t", "q", "v", "kinetic_energy", "potential_energy",
                                    "load_power", "min_gap", "negative_gaps")
               else "contacts" if name.startswith("contact_") else "steps")
        for name in ARRAYS}


def open_file(path: str | os.PathLike[str]) -> Any:
    """Creates (or truncates) the HDF5 file at ``path``; a path that cannot be written raises
    :class:`InvalidParameterError` naming it (before any step)."""
    import h5py

    try:
        return h5py.File(Path(path), "w")
    except (OSError, TypeError) as exc:
        raise InvalidParameterError(f"cannot write the trajectory file {str(path)!r}: {exc}"
                                    ) from exc


class CtrlC:
    """Records Ctrl-C during a streamed run, so that it stops the run even when its
    ``KeyboardInterrupt`` is lost.

    Python runs signal handlers between bytecodes, and a handler that runs inside a weakref
    callback or ``__del__`` raises into code whose exceptions are printed and ignored. h5py's
    objects die in such callbacks while a chunk is written, so a Ctrl-C could be swallowed
    there and the run went on (measured: 3 runs in 60 under load). While the context is
    open, SIGINT (on the main thread, where Python's default handler is installed) is handled
    by one that records it before raising; :meth:`check` raises ``KeyboardInterrupt`` once it
    has been recorded, and the writer checks at each chunk."""

    def __init__(self) -> None:
        self.seen = False
        self._previous: Any = None

    def _handler(self, signum: int, frame: Any) -> None:
        self.seen = True
        raise KeyboardInterrupt

    def __enter__(self) -> CtrlC:
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
            self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None

    def check(self) -> None:
        """Raises ``KeyboardInterrupt`` if Ctrl-C came since the context opened."""
        if self.seen:
            raise KeyboardInterrupt


class Writer:
    """Appends the chunks of a streamed run to an open HDF5 file (the ``write`` callable of
    ``coulomb._core.step_stream``): the contact records' ``contact_step`` is made the row in
    the whole file's step arrays. With ``ctrl_c``, a Ctrl-C recorded before a chunk stops the
    run there."""

    def __init__(self, f: Any, ctrl_c: CtrlC | None = None) -> None:
        self.f = f
        self.steps = 0
        self.failed = 0
        self.ctrl_c = ctrl_c

    def __call__(self, chunk: Mapping[str, Any]) -> None:
        import h5py

        if self.ctrl_c is not None:
            self.ctrl_c.check()
        offset = self.steps
        for name in ARRAYS:
            # a step's status comes as its code (STATUS_CODES)
            data = np.asarray(chunk[name], dtype=np.uint8 if name == "status" else None)
            if name == "contact_step":
                data = data + offset
            if name not in self.f:
                kw: dict[str, Any] = {}
                if name == "status":
                    kw["dtype"] = h5py.enum_dtype(STATUS_CODES, basetype="u1")
                # storage chunks of about 64 KiB: few enough that HDF5's index stays small
                row = max(1, data.itemsize * int(np.prod(data.shape[1:])))
                rows = max(1, 65536 // row)
                self.f.create_dataset(name, data=data, maxshape=(None, *data.shape[1:]),
                                      chunks=(rows, *data.shape[1:]), **kw)
                continue
            ds = self.f[name]
            n = ds.shape[0]
            ds.resize(n + len(data), axis=0)
            ds[n:] = data
        self.steps += len(chunk["active"])
        self.failed += int(np.count_nonzero(np.asarray(chunk["status"])
                                            > STATUS_CODES["solved"]))
        # the rows of whole chunks: a run stopped while a chunk was being appended is read
        # back up to the last whole one
        self.f.attrs.update(states=self.f["t"].shape[0], steps=self.steps,
                            contacts=self.f["contact_step"].shape[0])
        self.f.flush()


@dataclass(frozen=True)
class Streamed:
    """What :meth:`Scene.stream <coulomb.model.Scene.stream>` returns: where the trajectory
    went and how the run ended, without its arrays (:meth:`load` reads them back).

    ``success`` is true exactly when every step ran and every contact solve met its
    tolerance (as :attr:`Trajectory.success <coulomb.trajectory.Trajectory.success>`).

    The file holds one dataset per array of a trajectory, by the same names (``t``, ``q``,
    ``v``, the energies, ``load_power``, ``min_gap``, ``negative_gaps``, the step checks,
    ``status`` as an HDF5 enum of the status names, and the ``contact_*`` records,
    ``contact_step`` being the row in the file's step arrays), in storage chunks of about
    64 KiB, and the attributes ``format = "coulomb-trajectory"``, ``version``, ``dim``, ``h``,
    ``solver``, ``tol``, ``gap_tolerance``, ``record_every``, ``stopped`` (empty when every
    step ran), ``solve_time``, ``complete`` (false until the run ended: a run cut short by
    Ctrl-C says so) and ``states``, ``steps``, ``contacts`` (the rows of the whole chunks
    written)."""

    path: Path
    states: int
    steps: int
    failed_steps: int
    stopped: str | None
    solve_time: float
    chunks: int

    @property
    def status(self) -> Status:
        if self.stopped is not None:
            return Status.STOPPED
        return Status.SOLVER_FAILURES if self.failed_steps else Status.COMPLETED

    @property
    def success(self) -> bool:
        return self.status == Status.COMPLETED

    def load(self, scene: Scene | None = None) -> Trajectory:
        """The whole trajectory, read from the file into memory."""
        from .trajectory import Trajectory

        return Trajectory.load(self.path, scene=scene)

