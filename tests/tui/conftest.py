from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture(scope="session")
def compiled():
    return compile_package(open_spec(SPEC))


@pytest.fixture
def model_factory(compiled):
    from opspec.commands.walkthrough import _model_factory
    from opspec.usermodels import load_user_model

    return _model_factory(load_user_model(USERS), 0)
