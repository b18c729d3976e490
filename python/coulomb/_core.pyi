"""Type stub of the Rust extension ``coulomb._core``."""

from typing import Any

import numpy as np
from numpy.typing import NDArray

__version__: str

def lcp_solve(
    m: NDArray[np.float64],
    q: NDArray[np.float64],
    method: str,
    tol: float,
    max_pivots: int | None = None,
    covering_vector: NDArray[np.float64] | None = None,
    warm_start: list[int] | None = None,
    polish: bool = True,
    restarts: int = 2,
    max_iter: int = 10000,
    relaxation: float = 1.0,
    initial: NDArray[np.float64] | None = None,
    engine: str = "auto",
) -> dict[str, Any]: ...
def lcp_measures(
    m: NDArray[np.float64], q: NDArray[np.float64], z: NDArray[np.float64]
) -> dict[str, Any]: ...
def read_siconos_lcp(path: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
def contact_solve(
    w: NDArray[np.float64] | None,
    q: NDArray[np.float64],
    mu: NDArray[np.float64],
    dim: int,
    method: str,
    tol: float,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    initial: NDArray[np.float64] | None = None,
    facets: int | None = None,
    w_csr: tuple[
        int, NDArray[np.int32 | np.int64], NDArray[np.int32 | np.int64], NDArray[np.float64]
    ]
    | None = None,
    mu_pair: NDArray[np.float64] | None = None,
    eta: float | None = None,
    order: str = "forward",
    permutation: list[int] | None = None,
) -> dict[str, Any]: ...
def read_siconos_fc(path: str) -> dict[str, Any]: ...
def contact_solve_prox(
    w: NDArray[np.float64],
    q: NDArray[np.float64],
    mu: NDArray[np.float64],
    dim: int,
    tol: float,
    max_iter: int | None = None,
    eta: float = 0.1,
    initial: NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...

_Triplets = tuple[int, int, NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]

def contact_assemble(
    m: _Triplets,
    g: _Triplets,
    v_free: NDArray[np.float64] | None = None,
    force: NDArray[np.float64] | None = None,
    extra: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def contact_post_velocity(
    m: _Triplets, g: _Triplets, v_free: NDArray[np.float64], r: NDArray[np.float64]
) -> NDArray[np.float64]: ...
def simd_level() -> str: ...
def memory_budget() -> int: ...
def set_memory_budget(bytes: int) -> int: ...
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
) -> dict[str, Any]: ...
