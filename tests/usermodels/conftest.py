"""Fixtures of the user-model tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from .fakes import FakeSession

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def session() -> FakeSession:
    return FakeSession()


@pytest.fixture
def dispenser_users_path() -> Path:
    return REPO / "specs" / "medication_dispenser.users.toml"
