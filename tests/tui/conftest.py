from __future__ import annotations

import pytest

from opspec.engine.compiled import compile_package
from opspec.xpdl.open_spec import open_spec

from walkthrough_inputs import SPEC, USERS


@pytest.fixture(scope="session")
def compiled():
    return compile_package(open_spec(SPEC))


@pytest.fixture
def model_factory(compiled):
    from opspec.commands.walkthrough import _model_factory
    from opspec.usermodels import load_user_model

    return _model_factory(load_user_model(USERS), 0)
