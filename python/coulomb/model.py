r"""Scenes: bodies, contact shapes, half-spaces and contact pairs, simulated by Stewart's
(2000) impulse time stepper (the whole loop runs in Rust, with the GIL released).

A planar scene (``dim=2``) has particles ``(x, y)`` and planar rigid bodies ``(x, y, theta)``;
a spatial scene (``dim=3``) has particles ``(x, y, z)`` and spatial rigid bodies (position, unit
quaternion ``(w, x, y, z)``; velocities: linear, then the angular velocity in the world frame;
inertia in the body frame). The point shapes are sets of body-frame points with a radius
(:class:`Point`, :class:`Sphere`/:class:`Disk`, :class:`Segment` ends, :class:`Box` and
:class:`Polygon` corners): against a static :class:`HalfSpace` (floor, ramp, wall) they touch
by their points, a sphere against a sphere by the centres. Every shape with a volume is also a
solid (:class:`Sphere`, :class:`Box`, :class:`Polygon`, :class:`Segment` with a radius or in
2D, :class:`Capsule`, :class:`Cylinder`, :class:`Cone`, :class:`ConvexHull`,
:class:`Compound`; static :class:`TriangleMesh` and :class:`Heightfield` added to the scene),
and any two solids touch: each step the narrow phase (dimforge's parry, corrected) gives their
contact points. Pairs are declared by :meth:`Scene.contact` or found each step by a broad
phase (:meth:`Scene.contact_spheres`, :meth:`Scene.contact_all`), each with its friction
coefficient ``mu`` and Newton restitution coefficient ``e``.

>>> import coulomb
>>> scene = coulomb.Scene(dim=2, gravity=(0.0, -9.81))
>>> ball = scene.add(coulomb.Particle(mass=0.5, position=(0.0, 0.0), velocity=(0.0, -3.0)))
>>> floor = scene.add(coulomb.HalfSpace(point=(0.0, 0.0), normal=(0.0, 1.0)))
>>> scene.contact(scene.attach(ball, coulomb.Point()), floor, mu=0.0, e=0.6)
>>> tr = scene.simulate(t_end=0.002, h=0.001)
>>> round(float(tr.v[-1, 1]), 12)  # Newton: v_n^+ = -e v_n^- (then one step of gravity)
1.79019

Every step solves, with M and the Jacobians frozen at ``q_k``,
``v_{k+1} = v_free + M^-1 G P`` and ``q_{k+1} = q_k + h v_{k+1}``; see :mod:`coulomb.trajectory`
for the record and its checks. A closed contact gets Newton's condition
``0 <= P_n ⊥ J_n v_{k+1} + e v_n^- >= 0`` (or Poisson's law, ``restitution="poisson"``); an
imminently closing one the gap term ``J_n v_{k+1} + g / h >= 0`` (it may close within the step,
not pass through), and when that step pushes, the contact records its approach velocity and
the next step gives back the rebound ``-e v_n^-`` whatever gap is left (a rotating body or a
turning normal leaves O(h^2)); the record is then consumed. The rebound is exact wherever in
the step the impact falls when no force acts during the step; under a force such as gravity
the approach is the velocity at the start of the landing step, so with ``e = 1`` each bounce
loses ``m g y_k`` (``y_k`` the height there, at most ``m g h |v_n^-|``: first order in h).
In general the approach changes along the step at the gap's second derivative ``g''``, and a
bounce changes the energy by up to ``h m_eff |v_n^-| |g''|``: a gain where the normal turns
(two spheres passing obliquely: ``g'' = |v_t|^2 / d``). ``locate_impacts=True`` finds the
impact instant within the step for isolated impacts and removes both.

:class:`Model` takes a user-defined model in generalized coordinates instead (``M(q)``,
``f(q, v, t)`` and :class:`GapContact` gap functions with Jacobians), stepped by the same Rust
stepper, which calls those functions back at each state.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from . import _core, _scene_spec, _validate
from ._arguments import Solver, _dim, _positive, _solver_options, _steps, _vector
from ._batch import threads_option
from ._bodies import (
    Body,
    Box,
    Disk,
    HalfSpace,
    Particle,
    Point,
    Polygon,
    RigidBody2D,
    RigidBody3D,
    Segment,
    Sphere,
)
from ._extras import require
from ._generalized import GapContact, Model
from ._registry import _Registry
from ._solids import (
    Capsule,
    Compound,
    Cone,
    ConvexHull,
    Cylinder,
    Heightfield,
    Polyline,
    Shape,
    StaticSolid,
    TriangleMesh,
    _check_solid,
)
from .errors import InvalidParameterError
from .joints import Joint
from .settings import StepSettings, accepts
from .trajectory import Trajectory

if TYPE_CHECKING:
    from .trajectory import Streamed

__all__ = [
    "Body",
    "Box",
    "Capsule",
    "Compound",
    "Cone",
    "ConvexHull",
    "Cylinder",
    "Disk",
    "GapContact",
    "HalfSpace",
    "Heightfield",
    "Model",
    "Particle",
    "Point",
    "Polygon",
    "Polyline",
    "RigidBody2D",
    "RigidBody3D",
    "Scene",
    "Segment",
    "Shape",
    "Sphere",
    "TriangleMesh",
]




# --- scene ---------------------------------------------------------------------------------


class Scene:
    """A planar (``dim=2``) or spatial (``dim=3``) scene under uniform gravity (m/s^2)."""

    def __init__(self, dim: int = 2, gravity: Sequence[float] | None = None) -> None:
        _dim(dim)
        self.dim = int(dim)
        g = gravity if gravity is not None else [0.0] * (dim - 1) + [-9.81]
        self.gravity = _vector("gravity", g, dim)
        self.bodies: list[Body] = []
        self.half_spaces: list[HalfSpace] = []
        self.statics: list[StaticSolid] = []
        self.shapes: list[tuple[Body, Shape]] = []
        self.pairs: list[tuple[str, Any, Any, float, float]] = []
        self.joints: list[Joint] = []
        self._where = {"body": _Registry("body"), "half-space": _Registry("half-space"),
                       "static solid": _Registry("static solid"),
                       "shape": _Registry("shape", shapes=True)}

    def add(self, item: Body | HalfSpace | StaticSolid | Joint) -> Any:
        """Adds a body, a half-space, a static solid (:class:`TriangleMesh`,
        :class:`Heightfield`) or a joint (:mod:`coulomb.joints`); returns it (use it as a
        handle)."""
        if isinstance(item, Joint):
            item._spec(self.dim, self._body_index)  # checked now, before any work
            self.joints.append(item)
        elif isinstance(item, Body):
            item._spec(self.dim)  # checked now, before any work
            self.bodies.append(item)
            self._where["body"].appended(self.bodies)
        elif isinstance(item, HalfSpace):
            _vector("half-space point", item.point, self.dim)
            n = np.asarray(_vector("half-space normal", item.normal, self.dim))
            if not np.any(n != 0.0):
                raise InvalidParameterError("a half-space's normal must be nonzero")
            self.half_spaces.append(item)
            self._where["half-space"].appended(self.half_spaces)
        elif isinstance(item, StaticSolid):
            if self._where["static solid"].holds(self.statics, item):
                raise InvalidParameterError("this static solid was already added")
            _check_solid(item._solid(self.dim), self.dim)
            self.statics.append(item)
            self._where["static solid"].appended(self.statics)
        else:
            raise InvalidParameterError(f"cannot add {type(item).__name__} to a scene")
        return item

    def attach(self, body: Body, shape: Shape) -> Shape:
        """Attaches a contact shape to a body; returns the shape (a handle for contacts)."""
        self._body_index(body)
        if not isinstance(shape, Shape):
            raise InvalidParameterError(f"cannot attach {type(shape).__name__}: not a Shape")
        if self._where["shape"].holds(self.shapes, shape):
            raise InvalidParameterError("this shape is already attached to a body")
        shape._points(self.dim)
        if not shape._point_form:
            # a solid shape is checked now; a point shape's solid form (a polygon's hull) when
            # a pair needs it
            spec = shape._solid(self.dim)
            if spec is not None:
                _check_solid(spec, self.dim)
        self.shapes.append((body, shape))
        self._where["shape"].appended(self.shapes)
        return shape

    def _body_index(self, body: Any) -> int:
        return self._where["body"].index(self.bodies, body)

    def contact(self, shape: Shape, other: Shape | HalfSpace | StaticSolid, mu: float = 0.0,
                e: float = 0.0) -> None:
        """Declares that ``shape`` may touch ``other`` (a half-space, a static solid, or a
        shape on another body), with friction coefficient ``mu >= 0`` and Newton restitution
        ``e`` in [0, 1].

        A point shape against a half-space touches by its points (closed form), a sphere
        against a sphere by their centres; any other pair touches as solids, its contact points
        from the narrow phase each step (a :class:`Point` or a sphere of radius 0 has no
        solid). A pair declared here keeps its ``mu`` and ``e`` when :meth:`contact_all` finds
        it too."""
        mu = _validate.real("mu", mu, low=0.0, data=True)
        e = _validate.real("e", e, low=0.0, high=1.0, data=True)
        a = self._where["shape"].index(self.shapes, shape)
        if isinstance(other, HalfSpace):
            self._where["half-space"].index(self.half_spaces, other)
            if shape._point_form:
                self.pairs.append(("half_space", shape, other, mu, e))
            else:
                self.pairs.append(("solid_half_space", shape, other, mu, e))
            return
        if isinstance(other, StaticSolid):
            self._where["static solid"].index(self.statics, other)
            self._needs_solid(shape)
            self.pairs.append(("solid", shape, other, mu, e))
            return
        b = self._where["shape"].index(self.shapes, other)
        if self.shapes[a][0] is self.shapes[b][0]:
            raise InvalidParameterError("both shapes are on the same body")
        if isinstance(shape, Sphere) and isinstance(other, Sphere):
            self.pairs.append(("sphere", shape, other, mu, e))
            return
        self._needs_solid(shape)
        self._needs_solid(other)
        self.pairs.append(("solid", shape, other, mu, e))

    def _needs_solid(self, shape: Shape) -> None:
        form = shape._solid(self.dim)
        if form is not None and shape._point_form:
            _check_solid(form, self.dim)
        if form is None:
            raise InvalidParameterError(
                f"this {type(shape).__name__} has no solid form (a point, a sphere of radius 0, "
                "a 3D segment without radius, a polygon with a radius): it touches only "
                "half-spaces and spheres")

    def contact_spheres(self, mu: float = 0.0, e: float = 0.0) -> None:
        """Lets every pair of spheres on different bodies touch, with friction coefficient
        ``mu >= 0`` and Newton restitution ``e`` in [0, 1], without declaring the pairs: the
        stepper finds the pairs near each other itself every step (a broad phase, a uniform
        grid over the spheres, O(N) per step). The spheres are the single-point shapes
        (:class:`Sphere`; a :class:`Point` counts as a sphere of radius 0). A pair also
        declared with :meth:`contact` keeps that declaration's ``mu`` and ``e``. Contact ids
        of these pairs are ``D + i B + j`` (``D`` declared candidates, ``B`` spheres, ``i < j``
        the spheres' indices in the order they were attached). Not with :meth:`contact_all`,
        which covers the spheres too."""
        mu = _validate.real("mu", mu, low=0.0, data=True)
        e = _validate.real("e", e, low=0.0, high=1.0, data=True)
        if any(p[0] == "spheres" for p in self.pairs):
            raise InvalidParameterError("contact_spheres was already called on this scene")
        if any(p[0] == "solids" for p in self.pairs):
            raise InvalidParameterError(
                "contact_all already lets every pair of shapes touch, spheres included")
        self.pairs.append(("spheres", 0, 0, mu, e))

    def contact_all(self, mu: float = 0.0, e: float = 0.0) -> None:
        """Lets every pair of attached shapes on different bodies touch, and every attached
        shape touch every static solid (:class:`TriangleMesh`, :class:`Heightfield`), with
        friction coefficient ``mu >= 0`` and Newton restitution ``e`` in [0, 1], without
        declaring the pairs: the stepper finds the pairs whose bounding boxes (grown by what
        a step can close) meet, every step (a broad phase, a uniform grid, O(N) per step), and
        asks the narrow phase for their contact points. Every attached shape also touches
        every half-space (each pair as :meth:`contact` would declare it, after the declared
        pairs: a point shape by its points, a solid by the narrow phase). A pair declared by
        :meth:`contact` keeps that declaration's ``mu`` and ``e`` (per-pair overrides).
        Shapes of no volume (:class:`Point`, a sphere of radius 0, a :class:`Polygon` of
        collinear points) are left out of the shape pairs; against half-spaces they touch by
        their points.

        A contact found this way is named by its pair of shapes and its touching features,
        so warm starts and impact memory follow the same contact point from step to step;
        its ``contact_id`` is given when the contact first appears, above every id of the
        declared pairs and of :meth:`contact_spheres`, and kept while it persists."""
        mu = _validate.real("mu", mu, low=0.0, data=True)
        e = _validate.real("e", e, low=0.0, high=1.0, data=True)
        if any(p[0] == "solids" for p in self.pairs):
            raise InvalidParameterError("contact_all was already called on this scene")
        if any(p[0] == "spheres" for p in self.pairs):
            raise InvalidParameterError(
                "contact_spheres was called on this scene: contact_all covers the spheres too")
        self.pairs.append(("solids", 0, 0, mu, e))

    def _spec(self) -> dict[str, Any]:
        """the scene as the core reads it (module ``_scene_spec``)."""
        return _scene_spec.scene_spec(self)

    def layout(self) -> list[tuple[slice, slice]]:
        """The slices of each body's coordinates and velocities in ``q`` and ``v``."""
        out = []
        iq = iv = 0
        for b in self.bodies:
            nq = {"particle": self.dim, "planar": 3, "spatial": 7}[b.kind]
            nv = {"particle": self.dim, "planar": 3, "spatial": 6}[b.kind]
            out.append((slice(iq, iq + nq), slice(iv, iv + nv)))
            iq, iv = iq + nq, iv + nv
        return out

    @accepts(None, (StepSettings,))
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
        settings: StepSettings | None = None,
        threads: int | None = None,
    ) -> Trajectory:
        """Runs ``ceil(t_end / h)`` steps of the impulse time stepper from the initial state.

        Parameters
        ----------
        t_end, h : float
            Duration and time step (s), both > 0.
        solver : {"nsgs", "lemke"}
            The contact solver of every step: nonsmooth Gauss-Seidel on the exact friction disk
            (warm-started from the previous step's impulses of the same contacts) or the
            polyhedral-cone LCP by Lemke's method (``facets`` directions in 3D, default 8).
        tol : float, optional
            The contact solver's tolerance (default 1e-12 for NSGS, 1e-9 for Lemke).
        max_iter : int, optional
            NSGS sweeps (default 1000) or Lemke pivots (default ``max(1000, 50 n)``).
        relaxation : float
            NSGS relaxation in (0, 2).
        gap_tolerance : float
            A contact with gap at most this (m) is closed (restitution applies); above it, it is
            open and carries unknowns only if it could close within the step (gap term).
        warm_start : bool
            Start NSGS from the previous step's impulses.
        fallback : bool
            When NSGS misses its tolerance (singular, strongly coupled W), try in turn, the
            first passing answer taken, else the one of least exact-disk error (steps marked
            in ``fallback``; solved within ``max(tol, 1e-9)``): above 32 contacts the robust
            mode (proximal Newton, after 100 NSGS sweeps); up to 64 the polyhedral Lemke, then
            the robust mode from its answer; above 32 NSGS's remaining sweeps. With
            ``solver="lemke"``, when every Lemke path fails, NSGS on the exact disk from
            Lemke's impulses, kept (and marked) when it passes the exact rule.
        drift : {"none", "bias", "projection"}
            The position-drift correction (a velocity-level step does not enforce
            ``g(q_{k+1}) >= 0`` exactly): none; a velocity bias, a closed contact with ``g < 0``
            getting ``J_n v_{k+1} + e v_n^- + drift_bias g / h >= 0`` (pushes a fraction
            ``drift_bias`` in (0, 1] of the penetration out per step, adding kinetic energy);
            or a post-step projection onto ``g >= 0`` by the M-smallest displacement over
            every nearby contact (velocities untouched; its size per step is in
            ``projection``), which never deepens the worst penetration and never raises the
            energy (a lift against gravity is paid from what the step dissipated). Measured on
            five balls stacked 2 mm aside toppling (h = 1e-3, 1 s): worst penetration 1.6e-4 m
            without, 3.6e-4 m with the bias (energy gained in 289 steps), 2.0e-5 m with the
            projection (no step gaining energy).
        restitution : {"newton", "poisson"}
            The impact law at closed contacts, with each pair's ``e``: Newton's velocity-level
            condition ``J_n v_{k+1} + e v_n^- >= 0``, or Poisson's (an impact phase on ``v_k``:
            compression until the normal velocity stops, then the normal restitution impulse
            ``e P_comp``, Coulomb friction acting in both phases: Routh's integration in
            impulse space for one contact, which never gains energy, the two phases solved as
            wholes for coupled contacts). They agree on a single frictionless impact. Newton's
            law with friction can gain energy (a rod at 45 deg striking at v = (0.6, -1),
            e = 1, sticking: +0.1125 J); Poisson's does not.
        locate_impacts : bool
            Locate isolated impacts within the step (every active contact open, one reaching
            zero gap first): the step follows its free path to the impact instant, applies the
            impact law there and finishes the step from it. With ``e = 1`` under gravity the
            apex energy is then kept bounce after bounce (the plain step loses ``m g y_k`` per
            bounce, ``y_k`` the height at the start of the landing step). Other steps are
            plain steps.
        record_every : int
            Keep the state only after every ``record_every``-th step (and after the last); a
            kept step's checks (status, error, residuals, violations) are the worst over the
            steps since the previous kept one, so no failure is lost, and the contact records
            are those of the kept steps (``contact_step`` is then the row in the step
            arrays). The records grow as the run goes; their size is checked against
            ``coulomb.memory_budget()`` and a run that would exceed it is refused
            (:class:`~coulomb.errors.ProblemTooLargeError`, saying which ``record_every``
            fits).
        settings : StepSettings, optional
            Every option above as one object (:mod:`coulomb.settings`; its ``solver`` field an
            :class:`~coulomb.settings.NSGSSettings` or
            :class:`~coulomb.settings.PolyhedralSettings`). A keyword also given in it raises
            :class:`~coulomb.errors.SettingsConflictError`.
        threads : int, optional
            Threads each step's islands (groups of contacts no moving body links) are solved
            on, in [1, 1024] (default: all the cores); the trajectory is bitwise the same on any.

        Notes
        -----
        Counts are ints (``max_iter``, ``facets``, ``record_every``), ``t_end / h`` at most
        10^9 steps; options of the other solver are refused (``relaxation`` is NSGS's,
        ``facets`` Lemke's). Ctrl-C stops the run (``KeyboardInterrupt``).
        """
        args = self._run_args(t_end, h, solver, tol, max_iter, relaxation, facets,
                              gap_tolerance, warm_start, fallback, drift, drift_bias,
                              restitution, record_every, locate_impacts)
        raw = _core.step_simulate(self._spec(), **args, threads=threads_option(threads))
        return Trajectory._from_core(raw, scene=self, h=args["h"], solver=args["solver"],
                                     gap_tolerance=args["gap_tolerance"], tol=args["tol"],
                                     record_every=args["record_every"])

    def _run_args(self, t_end: float, h: float, solver: Solver, tol: float | None,
                  max_iter: int | None, relaxation: float, facets: int | None,
                  gap_tolerance: float, warm_start: bool, fallback: bool, drift: str,
                  drift_bias: float, restitution: str, record_every: int,
                  locate_impacts: bool) -> dict[str, Any]:
        """The checked options of :meth:`simulate` and :meth:`stream`, as the core's keywords."""
        t_end = _positive("t_end", t_end)
        h = _positive("h", h)
        steps = _steps(t_end, h)
        solver, tol, max_iter, relaxation, facets = _solver_options(
            self.dim, solver, tol, max_iter, relaxation, facets)
        gap_tolerance = _validate.real("gap_tolerance", gap_tolerance, low=0.0)
        warm_start = _validate.boolean("warm_start", warm_start)
        fallback = _validate.boolean("fallback", fallback)
        # drift, drift_bias and restitution are checked by the core (type, value, range)
        record_every = _validate.count("record_every", record_every)
        locate_impacts = _validate.boolean("locate_impacts", locate_impacts)
        if not self.bodies:
            raise InvalidParameterError("the scene has no bodies")
        return dict(h=h, steps=steps, solver=solver, tol=tol, max_iter=max_iter,
                    relaxation=relaxation, facets=facets, gap_tolerance=gap_tolerance,
                    warm_start=warm_start, fallback=fallback, drift=drift,
                    drift_bias=drift_bias, restitution=restitution, record_every=record_every,
                    locate_impacts=locate_impacts)

    @accepts(None, (StepSettings,))
    def stream(
        self,
        path: str | os.PathLike[str],
        t_end: float,
        h: float,
        solver: Solver = "nsgs",
        *,
        chunk: int = 1024,
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
        settings: StepSettings | None = None,
    ) -> Streamed:
        """:meth:`simulate`, writing the trajectory to the HDF5 file ``path`` as it goes
        (h5py, the optional extra ``coulomb[hdf5]``), so memory stays flat however long the
        run: the stepper hands its records out every ``chunk`` kept states (``chunk *
        record_every`` steps), each is appended to the file and dropped. The stepper's state
        (warm starts, impacts it stopped, persistent contacts) carries over between chunks:
        the file holds exactly the arrays :meth:`simulate` returns with the same options
        (its layout under :class:`~coulomb.trajectory.Streamed`); ``Trajectory.load(path)``
        reads it back.

        Returns a :class:`~coulomb.trajectory.Streamed`: the path, the counts of states and
        steps, ``status`` and ``success`` (as a trajectory's), ``stopped`` and the solve time.

        Raises
        ------
        MissingExtraError
            When h5py is not installed (before any work).
        InvalidParameterError
            When ``path`` cannot be written (before any step), or an option is invalid.

        Notes
        -----
        Ctrl-C stops the run (``KeyboardInterrupt``); the file then holds the chunks written
        so far and its ``complete`` attribute stays false.
        """
        require("h5py", extra="hdf5", what="Scene.stream")
        from . import _stream

        args = self._run_args(t_end, h, solver, tol, max_iter, relaxation, facets,
                              gap_tolerance, warm_start, fallback, drift, drift_bias,
                              restitution, record_every, locate_impacts)
        chunk = _validate.count("chunk", chunk)
        spec = self._spec()
        with _stream.open_file(path) as f, _stream.CtrlC() as ctrl_c:
            f.attrs.update(format=_stream.FORMAT, version=_stream.VERSION, dim=self.dim,
                           h=args["h"], solver=args["solver"], tol=args["tol"],
                           gap_tolerance=args["gap_tolerance"],
                           record_every=args["record_every"], complete=False)
            writer = _stream.Writer(f, ctrl_c)
            raw = _core.step_stream(spec, write=writer, chunk=chunk, **args)
            # a Ctrl-C whose KeyboardInterrupt was swallowed in a callback (see CtrlC)
            ctrl_c.check()
            stopped = raw["stopped"]
            f.attrs.update(stopped=stopped or "", solve_time=raw["solve_time"], complete=True)
            states = int(f["t"].shape[0]) if "t" in f else 0
        return _stream.Streamed(path=Path(path), states=states, steps=writer.steps,
                                failed_steps=writer.failed, stopped=stopped,
                                solve_time=float(raw["solve_time"]), chunks=int(raw["chunks"]))
