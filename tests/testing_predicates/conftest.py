"""Shared runs of the dispenser spec for the predicate, golden, assertion and monitor tests."""

from __future__ import annotations

from pathlib import Path

import pytest
import scipy.stats  # noqa: F401  (pytester inner runs must not import numpy/scipy again)

from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.testing.simulation import SimulationResult, load_spec_file, simulate

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
NINE = 9 * 3600.0


@pytest.fixture(scope="session")
def dispenser() -> CompiledPackage:
    return compile_package(load_spec_file(DISPENSER))


@pytest.fixture(scope="session")
def prompt_user(dispenser: CompiledPackage) -> SimulationResult:
    """One user who reports 90 s after the first alarm of the 08:00 dose (run to 09:00)."""
    return simulate(dispenser, script=[("after trg_2 90s", "press_report")], until=NINE)


@pytest.fixture(scope="session")
def absent_user(dispenser: CompiledPackage) -> SimulationResult:
    """One user who never reports: three alarms, a miss, the caregiver (run to 09:00)."""
    return simulate(dispenser, script=[("never", "press_report")], until=NINE)


@pytest.fixture
def pytester(pytester: pytest.Pytester) -> pytest.Pytester:
    pytester.makeini("[pytest]\naddopts = -p no:hypothesispytest -p no:cacheprovider\n"
                      "asyncio_default_fixture_loop_scope = function\n")
    return pytester
