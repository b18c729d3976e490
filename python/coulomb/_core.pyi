"""Type stub of the Rust extension ``coulomb._core`` (the bindings in ``rust/python/``).

Checked against the built extension by ``python -m mypy.stubtest coulomb._core``. ``lcp_solve``
and ``contact_solve`` return the package's result objects, filled by the core; the other
functions return plain dicts, whose keys and value types are the ``TypedDict`` classes below
(stub-only, hence private names).
"""

import os
from collections.abc import Callable
from typing import Any, Literal, TypedDict

import numpy as np
from numpy.typing import NDArray

from coulomb.contact import ContactResult
from coulomb.lcp import LcpResult

__all__ = [
    "__version__",
    "contact_assemble",
    "contact_post_velocity",
    "contact_solve",
    "contact_solve_batch",
    "lcp_measures",
    "lcp_solve",
    "lcp_solve_batch",
    "memory_budget",
    "model_simulate",
    "read_siconos_fc",
    "read_siconos_lcp",
    "set_memory_budget",
    "simd_level",
    "solid_check",
    "step_rollout",
    "step_simulate",
    "step_stream",
]

__version__: str

_F64 = NDArray[np.float64]
_I64 = NDArray[np.int64]
_Path = str | os.PathLike[str]

_LcpStatusName = Literal[
    "solved", "ray_termination", "pivot_limit", "iteration_limit", "numerical_failure",
    "no_solution",
]
_ContactStatusName = Literal["solved", "iteration_limit", "numerical_failure"]

class _LcpMeasuresDict(TypedDict):
    """``lcp_measures``: the error measures of a given z on (M, q)."""

    w: _F64
    error: float
    scaled_error: float
    min_z: float
    min_w: float
    max_complementarity: float

class _LcpBatchDict(TypedDict):
    """``lcp_solve_batch``: the answers column by column; ``z``, ``w`` flat, problem i at
    ``offsets[i]:offsets[i + 1]``; ``status`` and ``warm_start`` as codes (in the order of
    ``_LcpStatusName`` and none / accepted / rejected); ``basis`` in the layout of ``z``, its
    first ``basis_count[i]`` entries problem i's; ``solutions`` flat, ``solution_count[i]``
    vectors of problem i's size each; the messages as in ``_ContactBatchDict``."""

    z: _F64
    w: _F64
    offsets: _I64
    status: NDArray[np.uint8]
    warm_start: NDArray[np.uint8]
    error: _F64
    scaled_error: _F64
    min_z: _F64
    min_w: _F64
    max_complementarity: _F64
    pivots: _I64
    iterations: _I64
    pivots_saved: _I64
    restarts: _I64
    polished: NDArray[np.bool_]
    solve_time: _F64
    basis: _I64
    basis_count: _I64
    solutions: _F64
    solution_count: _I64
    message_slot: int
    message_bytes: NDArray[np.uint8]
    message_lengths: NDArray[np.uint16]
    message_overflow: dict[int, str]

class _ContactBatchDict(TypedDict):
    """``contact_solve_batch``: the answers column by column; ``impulse``, ``velocity`` flat,
    problem i at ``offsets[i]:offsets[i + 1]``; ``status`` as codes (in the order of
    ``_ContactStatusName``); problem i's message is the first ``message_lengths[i]`` UTF-8
    bytes of its slot ``message_bytes[i * message_slot:(i + 1) * message_slot]``, or
    ``message_overflow[i]`` when that length is 65535 (a message longer than a slot)."""

    impulse: _F64
    velocity: _F64
    offsets: _I64
    status: NDArray[np.uint8]
    iterations: _I64
    error: _F64
    error_q: _F64
    error_q_floor: _F64
    scaled_error: _F64
    min_normal_impulse: _F64
    max_complementarity: _F64
    cone_violation: _F64
    dissipation_violation: _F64
    solve_time: _F64
    message_slot: int
    message_bytes: NDArray[np.uint8]
    message_lengths: NDArray[np.uint16]
    message_overflow: dict[int, str]

class _SiconosLocalFcDict(TypedDict):
    """``read_siconos_fc`` of a local (``FC2D``/``FC3D``) problem."""

    kind: Literal["local"]
    dim: int
    nc: int
    W: _F64
    q: _F64
    mu: _F64

class _SiconosGlobalFcDict(TypedDict):
    """``read_siconos_fc`` of a global (``GFC3D``) problem."""

    kind: Literal["global"]
    dim: int
    nc: int
    M: _F64
    H: _F64
    q: _F64
    b: _F64
    mu: _F64

class _StepSimulateDict(TypedDict):
    """``step_simulate``: the recorded trajectory, one row per recorded step."""

    dim: int
    t: _F64
    q: _F64
    v: _F64
    kinetic_energy: _F64
    potential_energy: _F64
    min_gap: _F64
    negative_gaps: _I64
    active: _I64
    status: NDArray[np.uint8]
    """each step's status as its code: ``STATUS_CODES`` of ``coulomb._stream``."""
    error: _F64
    scaled_error: _F64
    error_q: _F64
    error_q_floor: _F64
    iterations: _I64
    momentum_residual: _F64
    min_normal_impulse: _F64
    cone_violation: _F64
    complementarity: _F64
    resumed: NDArray[np.bool_]
    fallback: NDArray[np.bool_]
    projection: _F64
    contact_step: _I64
    contact_id: _I64
    contact_impulse: _F64
    contact_velocity: _F64
    contact_approach: _F64
    contact_gap: _F64
    contact_closed: NDArray[np.bool_]
    stopped: str | None
    solve_time: float

class _StepStreamDict(TypedDict):
    """``step_stream``: how the streamed run ended."""

    stopped: str | None
    solve_time: float
    chunks: int

class _ModelSimulateDict(_StepSimulateDict):
    """``model_simulate``: a scene's trajectory dict and ``f . v`` per recorded state."""

    load_power: _F64

def lcp_solve(
    m: _F64,
    q: _F64,
    method: str,
    tol: float,
    max_pivots: int | None = None,
    covering_vector: _F64 | None = None,
    warm_start: list[int] | None = None,
    polish: bool = True,
    restarts: int = 2,
    max_iter: int = 10000,
    relaxation: float = 1.0,
    initial: _F64 | None = None,
    engine: str = "auto",
) -> LcpResult: ...
def lcp_measures(m: _F64, q: _F64, z: _F64) -> _LcpMeasuresDict: ...
def read_siconos_lcp(path: _Path) -> tuple[_F64, _F64]: ...
def contact_solve(
    w: _F64 | None,
    q: _F64,
    mu: _F64,
    dim: int,
    method: str,
    tol: float,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    initial: _F64 | None = None,
    facets: int | None = None,
    w_csr: tuple[int, NDArray[np.int32 | np.int64], NDArray[np.int32 | np.int64], _F64]
    | None = None,
    mu_pair: _F64 | None = None,
    eta: float | None = None,
    order: str = "forward",
    permutation: list[int] | None = None,
    sticking: bool = True,
) -> ContactResult: ...
def lcp_solve_batch(
    ms: _F64 | list[_F64],
    qs: _F64 | list[_F64],
    method: str,
    tol: float,
    max_pivots: int | None = None,
    covering_vector: list[_F64 | None] | None = None,
    warm_start: list[list[int] | None] | None = None,
    polish: bool = True,
    restarts: int = 2,
    max_iter: int = 10000,
    relaxation: float = 1.0,
    initial: list[_F64 | None] | None = None,
    engine: str = "auto",
    threads: int | None = None,
) -> _LcpBatchDict: ...
def contact_solve_batch(
    ws: _F64 | list[_F64],
    qs: _F64 | list[_F64],
    mus: _F64 | list[_F64],
    dim: int,
    method: str,
    tol: float,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    initial: list[_F64 | None] | None = None,
    facets: int | None = None,
    mu_pairs: list[_F64 | None] | None = None,
    eta: float | None = None,
    order: str = "forward",
    threads: int | None = None,
    sticking: bool = True,
) -> _ContactBatchDict: ...
def read_siconos_fc(path: _Path) -> _SiconosLocalFcDict | _SiconosGlobalFcDict: ...

_Triplets = tuple[int, int, _I64, _I64, _F64]

def contact_assemble(
    m: _Triplets,
    g: _Triplets,
    v_free: _F64 | None = None,
    force: _F64 | None = None,
    extra: _F64 | None = None,
) -> tuple[_F64, _F64, _F64]: ...
def contact_post_velocity(m: _Triplets, g: _Triplets, v_free: _F64, r: _F64) -> _F64: ...
def simd_level() -> str: ...
def memory_budget() -> int: ...
def set_memory_budget(bytes: int) -> int: ...
def solid_check(solid: dict[str, Any], dim: int) -> None: ...
def step_simulate(
    scene: dict[str, Any],
    h: float,
    steps: int,
    solver: str = "nsgs",
    tol: float = 1e-12,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    facets: int | None = None,
    gap_tolerance: float = 1e-9,
    warm_start: bool = True,
    fallback: bool = True,
    drift: str = "none",
    drift_bias: float = 0.2,
    restitution: str = "newton",
    record_every: int = 1,
    locate_impacts: bool = False,
    threads: int | None = None,
) -> _StepSimulateDict: ...
def step_rollout(
    scenes: list[dict[str, Any]],
    options: list[dict[str, Any]],
    threads: int | None = None,
) -> list[_StepSimulateDict]: ...
def step_stream(
    scene: dict[str, Any],
    h: float,
    steps: int,
    write: Callable[[_StepSimulateDict], object],
    chunk: int = 1024,
    solver: str = "nsgs",
    tol: float = 1e-12,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    facets: int | None = None,
    gap_tolerance: float = 1e-9,
    warm_start: bool = True,
    fallback: bool = True,
    drift: str = "none",
    drift_bias: float = 0.2,
    restitution: str = "newton",
    record_every: int = 1,
    locate_impacts: bool = False,
) -> _StepStreamDict: ...
def model_simulate(
    dim: int,
    laws: list[tuple[float, float]],
    mass: Callable[[_F64], _F64],
    force: Callable[[_F64, _F64, float], _F64] | None,
    contacts: Callable[[_F64], _F64] | None,
    potential: Callable[[_F64], float] | None,
    q0: list[float],
    v0: list[float],
    h: float,
    steps: int,
    solver: str = "nsgs",
    tol: float = 1e-12,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    facets: int | None = None,
    gap_tolerance: float = 1e-9,
    warm_start: bool = True,
    fallback: bool = True,
    drift: str = "none",
    drift_bias: float = 0.2,
    restitution: str = "newton",
    record_every: int = 1,
    locate_impacts: bool = False,
) -> _ModelSimulateDict: ...
