"""pytester (pytest's own test-the-plugin fixture) for this package only."""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

import pytest
import scipy.stats  # noqa: F401

import opspec.engine

# pytester's in-process runs drop the modules an inner run imported; numpy (and so the engine)
# cannot be imported twice in one process, so everything the inner runs use is imported here:
# the whole engine too (a compiled module that imports another lazily finds it gone, and this
# folder run alone failed every scenario test that way).
for _module in pkgutil.walk_packages(opspec.engine.__path__, "opspec.engine."):
    importlib.import_module(_module.name)

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture
def pytester(pytester: pytest.Pytester) -> pytest.Pytester:
    """pytester whose inner runs skip hypothesis's plugin (it costs ~2 s per in-process run
    and these tests do not use it)."""
    pytester.makeini("[pytest]\naddopts = -p no:hypothesispytest -p no:cacheprovider\n"
                      "asyncio_default_fixture_loop_scope = function\n")
    return pytester


@pytest.fixture
def project(pytester: pytest.Pytester) -> pytest.Pytester:
    """A pytester directory holding a copy of the dispenser spec and its user model."""
    (pytester.path / "specs").mkdir()
    (pytester.path / "specs" / "dispenser.xpdl").write_bytes(DISPENSER.read_bytes())
    (pytester.path / "specs" / "dispenser.users.toml").write_bytes(USERS.read_bytes())
    return pytester
