"""Fixtures for the engine tests (models are built in builders.py; running a package and reading
its trace in engine_runs.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from opspec.engine.config import EngineConfig  # noqa: E402

MODELS = {
    "dedicated": EngineConfig(),
    "pooled": EngineConfig(processor_model="pooled", workers=2, switch_cost=0.001),
}


@pytest.fixture(params=list(MODELS), ids=list(MODELS))
def config(request: pytest.FixtureRequest) -> EngineConfig:
    """Each pattern test runs under both processor models."""
    return MODELS[request.param]
