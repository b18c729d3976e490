"""Many scenes simulated at once across the cores: :func:`rollout`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

from . import _core
from ._arguments import Solver
from ._batch import at_problem, threads_option
from .errors import ArgumentTypeError
from .model import Scene
from .settings import StepSettings, accepts
from .trajectory import Trajectory

__all__ = ["rollout"]


@accepts(None, (StepSettings,))
def rollout(
    scenes: Sequence[Scene],
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
) -> list[Trajectory]:
    """Simulate many scenes at once, across the cores: one trajectory per scene, in order.

    Each scene runs exactly as :meth:`Scene.simulate <coulomb.model.Scene.simulate>` runs it
    alone with the same options (the same stepper, its own state): every trajectory is
    bitwise the one-at-a-time run's, whatever ``threads``. The scenes may differ in every
    respect (bodies, shapes, dimension). The GIL is released for the whole rollout and Ctrl-C
    stops it (``KeyboardInterrupt``).

    Parameters
    ----------
    scenes : sequence of Scene
        The scenes, each from its initial state.
    t_end, h, solver, tol, max_iter, relaxation, facets, gap_tolerance, warm_start, fallback, \
drift, drift_bias, restitution, record_every, locate_impacts, settings
        As for :meth:`Scene.simulate <coulomb.model.Scene.simulate>`, the same for every scene.
    threads : int, optional
        Threads to simulate on, in [1, 1024] (default: all the cores).

    Returns
    -------
    list of Trajectory

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError, ProblemTooLargeError
        Before any step, as :meth:`Scene.simulate <coulomb.model.Scene.simulate>` raises them;
        the message names the scene's index.
    """
    if isinstance(scenes, Scene) or not isinstance(scenes, Sequence):
        raise ArgumentTypeError(
            f"scenes must be a sequence of Scene, got {type(scenes).__name__}")
    for i, s in enumerate(scenes):
        if not isinstance(s, Scene):
            raise ArgumentTypeError(f"scenes[{i}] must be a Scene, got {type(s).__name__}")
    n_threads = threads_option(threads)
    # the options depend on a scene only through its dimension (and its having bodies):
    # checked once per dimension, each scene given that dict
    checked: dict[int, dict[str, Any]] = {}
    options = []
    for i, s in enumerate(scenes):
        a = checked.get(s.dim)
        if a is None or not s.bodies:
            a = at_problem(i, s._run_args, t_end, h, solver, tol, max_iter, relaxation,
                           facets, gap_tolerance, warm_start, fallback, drift, drift_bias,
                           restitution, record_every, locate_impacts, what="scene")
            checked[s.dim] = a
        options.append(a)
    specs = [at_problem(i, s._spec, what="scene") for i, s in enumerate(scenes)]
    raws = _core.step_rollout(specs, options, n_threads)
    return [Trajectory._from_core(raw, scene=s, h=a["h"], solver=a["solver"],
                                  gap_tolerance=a["gap_tolerance"], tol=a["tol"],
                                  record_every=a["record_every"])
            for raw, s, a in zip(raws, scenes, options, strict=True)]
