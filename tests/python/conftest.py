"""Shared fixtures: where the benchmark data lives."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# The files of ../shared/data/siconos-lcp (see SOURCE.md there).
SICONOS_LCP_NAMES = (
    "lcp_CPS_1",
    "lcp_CPS_2",
    "lcp_CPS_3",
    "lcp_CPS_4",
    "lcp_CPS_4bis",
    "lcp_CPS_5",
    "lcp_Pang_isolated_sol",
    "lcp_Pang_isolated_sol_perturbed",
    "lcp_deudeu",
    "lcp_deudeu_block",
    "lcp_enum_fails",
    "lcp_exp_murty",
    "lcp_exp_murty2",
    "lcp_inf_sol_perturbed",
    "lcp_mmc",
    "lcp_ortiz",
    "lcp_ortiz_block",
    "lcp_tobenna",
    "lcp_trivial",
    "lcp_trivial_block",
)


def find_data_dir() -> Path:
    """``$COULOMB_DATA`` if set, else ``<checkout>/../shared/data``."""
    env = os.environ.get("COULOMB_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3] / "shared" / "data"


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The benchmark data folder; skips the test when it is absent."""
    path = find_data_dir()
    if not (path / "siconos-lcp").is_dir():
        pytest.skip(f"benchmark data not found at {path}; set COULOMB_DATA")
    return path


@pytest.fixture(scope="session")
def siconos_lcp_dir(data_dir: Path) -> Path:
    return data_dir / "siconos-lcp"
