"""Shared fixtures: where the benchmark data lives (see helpers.py: tests/data first, then
``$COULOMB_DATA`` or ``../shared/data``)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from helpers import SHIPPED, external_data_dir, full_set_dir, shipped_dir
from hypothesis import settings

# Property tests draw the same examples on every run unless COULOMB_PROPERTIES=long asks for a
# fresh random search: a CI run cannot flake on an example no earlier run has seen.
settings.register_profile("coulomb", derandomize=os.environ.get("COULOMB_PROPERTIES") != "long")
settings.load_profile("coulomb")

# The files of tests/data/siconos-lcp (see SOURCE.md there).
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
    """``$COULOMB_DATA`` if set, else ``<checkout>/../shared/data`` (the full sets)."""
    return external_data_dir()


@pytest.fixture(scope="session")
def shipped_data() -> Path:
    """``tests/data``: a data folder with the whole Siconos LCP set and subsets of the others."""
    shipped_dir("siconos-lcp")
    return SHIPPED


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The full benchmark data folder; skips the test when it is absent (fails in CI)."""
    for name in ("siconos-lcp", "siconos-fc", "fclib"):
        full_set_dir(name)
    return external_data_dir()


@pytest.fixture(scope="session")
def siconos_lcp_dir() -> Path:
    """The Siconos LCP set: it ships whole in tests/data."""
    return shipped_dir("siconos-lcp")


def pytest_collection_finish(session: pytest.Session) -> None:
    """A run with no test to run is an error, never a quiet pass: it says why."""
    if not session.items and not session.testsfailed and not session.config.option.collectonly:
        raise pytest.UsageError(
            "no test to run (none collected, or every one deselected by -k/-m): run pytest "
            "from the repository root, where pyproject.toml sets testpaths = tests/python"
        )
