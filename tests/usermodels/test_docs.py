"""The TOML examples in docs/user-models.md load (the documentation cannot rot silently)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from opspec.usermodels import parse_user_model

DOC = Path(__file__).resolve().parents[2] / "docs" / "user-models.md"
BLOCKS = re.findall(r"```toml\n(.*?)```", DOC.read_text(encoding="utf-8"), re.DOTALL)


def test_the_docs_have_toml_examples() -> None:
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("block", BLOCKS, ids=[f"example-{i}" for i in range(len(BLOCKS))])
def test_each_toml_example_in_the_docs_loads(block: str) -> None:
    model = parse_user_model(tomllib.loads(block), "docs/user-models.md")
    assert model.name


def test_the_full_example_covers_the_dispenser_lane() -> None:
    model = parse_user_model(tomllib.loads(BLOCKS[0]), "docs/user-models.md")
    assert model.validate_against(
        ["hear_alarm", "walk_to_dispenser", "press_report", "press_wrong_button", "take_pill"],
        choices={"choose_button": ["press_report", "press_wrong_button"]}) == []
