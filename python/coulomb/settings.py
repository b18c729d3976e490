"""Settings objects: a solver's options as one frozen value, checked when made.

:func:`coulomb.lcp.solve`, :func:`coulomb.contact.solve` and :meth:`coulomb.Scene.simulate`
take ``settings=`` instead of their long keyword lists; the keywords keep working. A settings
object chooses the method (``LemkeSettings`` is ``method="lemke"``, ...); giving it together
with a keyword for one of its fields, or with another method, raises
:class:`~coulomb.errors.SettingsConflictError`. Keywords that are not settings (the data of one
problem: ``warm_start``, ``initial``) combine freely with a settings object.

>>> import coulomb
>>> fast = coulomb.NSGSSettings(tol=1e-6, max_iter=200)
>>> fast
NSGSSettings(tol=1e-06, max_iter=200, relaxation=1.0, order='forward', sticking=True)
>>> r = coulomb.contact.solve([[0.5, 0.0], [0.0, 0.5]], [-3.0, 1.0], 0.2, dim=2, settings=fast)
>>> r.status, r.impulse.round(12).tolist()
(Status.SOLVED, [[6.0, -1.2]])

A field left at ``None`` takes the default of the call it is given to (``tol`` is 1e-8 in
:func:`coulomb.contact.solve`, 1e-12 for NSGS and 1e-9 for Lemke in the stepper).
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, ParamSpec, TypeVar

from . import _validate
from .errors import ArgumentTypeError, InvalidParameterError, SettingsConflictError

__all__ = [
    "LemkeSettings",
    "NSGSSettings",
    "PGSSettings",
    "PolyhedralSettings",
    "ProxSettings",
    "StepSettings",
]

#: the most covering vectors Lemke tries after the first (Rust ``lcp::lemke::MAX_RESTARTS``).
_MAX_RESTARTS = 1000


def _tol(value: float | None) -> None:
    if value is not None:
        _validate.tolerance("tol", value)


@dataclass(frozen=True)
class LemkeSettings:
    """Lemke's method for an LCP (:func:`coulomb.lcp.solve`, ``method="lemke"``).

    Attributes
    ----------
    tol : float
        Tolerance on ``error`` and ``scaled_error`` for ``success``, in (0, 1); default 1e-9.
    max_pivots : int or None
        Pivot limit in [1, 10^9]; None: ``max(1000, 50 n)``.
    covering_vector : tuple of float or None
        Lemke's covering vector d > 0 (in the units of q); None: all ones on the
        equilibrated problem.
    polish : bool
        Re-solve the final basis's principal system and keep it if better (default True).
    restarts : int
        Other covering vectors tried after a ray termination or a terminal basis whose
        answer fails ``tol``, in [0, 1000] (default 2).
    engine : {"auto", "tableau", "product_form"}
        How the basis inverse is kept (default ``"auto"``).
    """

    tol: float = 1e-9
    max_pivots: int | None = None
    covering_vector: tuple[float, ...] | None = None
    polish: bool = True
    restarts: int = 2
    engine: Literal["auto", "tableau", "product_form"] = "auto"

    def __post_init__(self) -> None:
        _validate.tolerance("tol", self.tol)
        _validate.optional_count("max_pivots", self.max_pivots)
        if self.covering_vector is not None:
            d = _validate.finite_array(self.covering_vector, "covering_vector", 1)
            object.__setattr__(self, "covering_vector", tuple(float(x) for x in d))
        _validate.boolean("polish", self.polish)
        _validate.count("restarts", self.restarts, minimum=0, maximum=_MAX_RESTARTS)
        _validate.choice("engine", self.engine, ("auto", "tableau", "product_form"))


@dataclass(frozen=True)
class PGSSettings:
    """Projected Gauss-Seidel for an LCP (:func:`coulomb.lcp.solve`, ``method="pgs"``).

    Attributes
    ----------
    tol : float
        Tolerance for ``success``, in (0, 1); default 1e-9.
    max_iter : int
        Sweep limit in [1, 10^9] (default 10,000).
    relaxation : float
        Over-relaxation in (0, 2) (default 1).
    """

    tol: float = 1e-9
    max_iter: int = 10_000
    relaxation: float = 1.0

    def __post_init__(self) -> None:
        _validate.tolerance("tol", self.tol)
        _validate.count("max_iter", self.max_iter)
        _validate.real("relaxation", self.relaxation, low=0.0, high=2.0, low_open=True,
                       high_open=True)


@dataclass(frozen=True)
class NSGSSettings:
    """Nonsmooth Gauss-Seidel on the exact friction disk (:func:`coulomb.contact.solve`
    ``method="nsgs"``; the stepper's ``solver="nsgs"``).

    Attributes
    ----------
    tol : float or None
        Tolerance on ``scaled_error``, in (0, 1); None: the call's default (1e-8 in
        :func:`coulomb.contact.solve`, 1e-12 in the stepper).
    max_iter : int or None
        Sweep limit (at least 1); None: 1000.
    relaxation : float
        Relaxation in (0, 2); 1 is plain Gauss-Seidel (default).
    order : {"forward", "backward", "symmetric"}
        The order a sweep visits the contacts in (default ``"forward"``; the stepper sweeps
        forward only).
    sticking : bool
        When the sweeps slow down, and in :func:`coulomb.contact.solve` once more when
        ``max_iter`` is spent, also try the exact solve on the contacts' current cases
        (default True; the stepper always does, and leaves a step its sweeps do not solve to
        its fallbacks). False: plain Gauss-Seidel sweeps.

    Notes
    -----
    The sticking-set solve: when the sweeps slow down, NSGS also tries the exact answer on
    the contacts' current cases (stick, slide, separate), the least-norm impulses of the
    sticking set, and keeps it only when it passes the tolerance or halves ``scaled_error``.
    It fixes the impulses of redundant face contacts (four corners of a box on a box), where
    the sweeps drift along W's null directions: a ten-box tower then stands with drift at
    rounding over 10 s at h = 1 ms.
    """

    tol: float | None = None
    max_iter: int | None = None
    relaxation: float = 1.0
    order: Literal["forward", "backward", "symmetric"] = "forward"
    sticking: bool = True

    def __post_init__(self) -> None:
        _tol(self.tol)
        _validate.optional_count("max_iter", self.max_iter)
        _validate.real("relaxation", self.relaxation, low=0.0, high=2.0, low_open=True,
                       high_open=True)
        _validate.choice("order", self.order, ("forward", "backward", "symmetric"))
        _validate.boolean("sticking", self.sticking)


@dataclass(frozen=True)
class PolyhedralSettings:
    """Stewart and Trinkle's polyhedral-cone LCP by Lemke's method
    (:func:`coulomb.contact.solve` ``method="lemke"``; the stepper's ``solver="lemke"``).

    Attributes
    ----------
    tol : float or None
        Tolerance, in (0, 1); None: the call's default (1e-8 in :func:`coulomb.contact.solve`,
        1e-9 in the stepper).
    max_iter : int or None
        Pivot limit (at least 1); None: ``max(1000, 50 n)`` for n LCP unknowns.
    facets : int or None
        Tangent directions per frictional contact in +/- pairs (2 in 2D; even and at least 4
        in 3D); None: 2 in 2D, 8 in 3D.
    """

    tol: float | None = None
    max_iter: int | None = None
    facets: int | None = None

    def __post_init__(self) -> None:
        _tol(self.tol)
        _validate.optional_count("max_iter", self.max_iter)
        _validate.optional_count("facets", self.facets, minimum=2,
                                 maximum=_validate.MAX_FACETS)
        if self.facets is not None and self.facets % 2:
            raise InvalidParameterError(
                f"facets must be even (tangent directions in +/- pairs), got {self.facets}")


@dataclass(frozen=True)
class ProxSettings:
    """The robust mode, proximal-point semismooth Newton (:func:`coulomb.contact.solve`
    ``method="prox"``).

    Attributes
    ----------
    tol : float
        Tolerance on ``scaled_error``, in (0, 1); default 1e-8.
    max_iter : int
        Newton steps at most (default 200).
    eta : float
        The initial proximal parameter relative to W's mean diagonal, > 0 (default 0.1).
    """

    tol: float = 1e-8
    max_iter: int = 200
    eta: float = 0.1

    def __post_init__(self) -> None:
        _validate.tolerance("tol", self.tol)
        _validate.count("max_iter", self.max_iter)
        _validate.real("eta", self.eta, low=0.0, low_open=True)


def _nsgs_for_steps() -> NSGSSettings:
    return NSGSSettings()


@dataclass(frozen=True)
class StepSettings:
    """The impulse time stepper's options (:meth:`coulomb.Scene.simulate`; see it for what
    each one does).

    Attributes
    ----------
    solver : NSGSSettings or PolyhedralSettings
        The contact solver of every step (default NSGS, tolerance 1e-12).
    gap_tolerance : float
        A contact with gap at most this (m) is closed (default 1e-9).
    warm_start : bool
        Start NSGS from the previous step's impulses (default True).
    fallback : bool
        Try another method when NSGS misses its tolerance (default True).
    drift : {"none", "bias", "projection"}
        The position-drift correction (default ``"none"``).
    drift_bias : float
        The fraction of a penetration the velocity bias pushes out per step, in (0, 1]
        (default 0.2).
    restitution : {"newton", "poisson"}
        The impact law (default ``"newton"``).
    record_every : int
        Keep every ``record_every``-th state (default 1).
    locate_impacts : bool
        Locate isolated impacts within the step (default False).
    """

    solver: NSGSSettings | PolyhedralSettings = field(default_factory=_nsgs_for_steps)
    gap_tolerance: float = 1e-9
    warm_start: bool = True
    fallback: bool = True
    drift: Literal["none", "bias", "projection"] = "none"
    drift_bias: float = 0.2
    restitution: Literal["newton", "poisson"] = "newton"
    record_every: int = 1
    locate_impacts: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.solver, (NSGSSettings, PolyhedralSettings)):
            raise ArgumentTypeError(
                "solver must be NSGSSettings or PolyhedralSettings, got "
                f"{type(self.solver).__name__}")
        if isinstance(self.solver, NSGSSettings) and self.solver.order != "forward":
            raise InvalidParameterError(
                "the stepper's NSGS sweeps the contacts forward: leave order out")
        if isinstance(self.solver, NSGSSettings) and not self.solver.sticking:
            raise InvalidParameterError(
                "the stepper's NSGS always tries the sticking-set solve (a face's redundant "
                "contacts drift without it): leave sticking out")
        _validate.real("gap_tolerance", self.gap_tolerance, low=0.0)
        _validate.boolean("warm_start", self.warm_start)
        _validate.boolean("fallback", self.fallback)
        _validate.choice("drift", self.drift, ("none", "bias", "projection"), "drift correction")
        _validate.real("drift_bias", self.drift_bias, low=0.0, high=1.0, low_open=True)
        _validate.choice("restitution", self.restitution, ("newton", "poisson"), "impact law")
        _validate.count("record_every", self.record_every)
        _validate.boolean("locate_impacts", self.locate_impacts)


# --- how a call takes a settings object ---------------------------------------------------

#: the method each settings class stands for, per call kind.
_METHOD_OF: dict[type, str] = {
    LemkeSettings: "lemke",
    PGSSettings: "pgs",
    NSGSSettings: "nsgs",
    PolyhedralSettings: "lemke",
    ProxSettings: "prox",
}


def _keywords(settings: Any) -> dict[str, Any]:
    """The keywords a settings object stands for (None fields left to the call's default)."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(settings):
        value = getattr(settings, f.name)
        if isinstance(value, (NSGSSettings, PolyhedralSettings)):
            out["solver"] = _METHOD_OF[type(value)]
            sub = _keywords(value)
            # the stepper sweeps forward and tries the sticking set (checked in StepSettings)
            sub.pop("order", None)
            sub.pop("sticking", None)
            out.update(sub)
        elif value is not None:
            out[f.name] = value
    return out


def _field_names(settings: Any) -> set[str]:
    names = set()
    for f in dataclasses.fields(settings):
        value = getattr(settings, f.name)
        if isinstance(value, (NSGSSettings, PolyhedralSettings)):
            names |= ({"solver"} | {g.name for g in dataclasses.fields(value)}
                      - {"order", "sticking"})
        else:
            names.add(f.name)
    return names


P = ParamSpec("P")
R = TypeVar("R")


def accepts(method_param: str | None, classes: tuple[type, ...]
            ) -> Callable[[Callable[P, R]], Callable[P, R]]:
    """Lets a function take ``settings=`` (one of ``classes``) in place of its keywords:
    the object's fields become keywords, and it chooses ``method_param`` (unless that is the
    stepper's ``solver``, which the object's ``solver`` field gives). A keyword given with the
    object for one of its fields, or a method that is not the object's, raises
    :class:`SettingsConflictError`."""

    def wrap(fn: Callable[P, R]) -> Callable[P, R]:
        signature = inspect.signature(fn)

        @functools.wraps(fn)
        def call(*args: P.args, **kwargs: P.kwargs) -> R:
            settings = kwargs.get("settings")
            if settings is None:
                return fn(*args, **kwargs)
            if not isinstance(settings, classes):
                names = " or ".join(c.__name__ for c in classes)
                raise ArgumentTypeError(
                    f"settings must be {names}, got {type(settings).__name__}")
            given: Mapping[str, Any] = signature.bind(*args, **kwargs).arguments
            both = sorted(_field_names(settings) & (set(given) - {"settings"}))
            if method_param is not None and method_param in given:
                wanted = _METHOD_OF[type(settings)]
                if given[method_param] != wanted:
                    raise SettingsConflictError(
                        f"{method_param}={given[method_param]!r} does not match "
                        f"{type(settings).__name__} (method {wanted!r}): give one of them")
                both = [b for b in both if b != method_param]
            if both:
                raise SettingsConflictError(
                    f"{', '.join(both)} given both as keyword and in {type(settings).__name__}:"
                    " give each setting once")
            bound = dict(given)
            bound.pop("settings")
            bound.update(_keywords(settings))
            if method_param is not None and method_param != "solver":
                bound[method_param] = _METHOD_OF[type(settings)]
            return fn(**bound)  # type: ignore[call-arg, arg-type]

        return call

    return wrap
