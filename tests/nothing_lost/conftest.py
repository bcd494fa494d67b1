"""The dispenser with a run-time fault on its rarest branch, shared by the tests that follow
a fault through evaluate and through simulate()."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
# the second re-alarm (alarms == 2) divides by zero: the dispenser's rarest branch
BROKEN = "alarms &lt; 3 and 1 / (alarms - 2) &gt; -99"


@pytest.fixture
def broken_spec(tmp_path: Path) -> Path:
    text = SPEC.read_text(encoding="utf-8")
    assert text.count("<Expression>alarms &lt; 3</Expression>") == 1
    spec = tmp_path / "medication_dispenser.xpdl"
    spec.write_text(text.replace("<Expression>alarms &lt; 3</Expression>",
                                 f"<Expression>{BROKEN}</Expression>"), encoding="utf-8")
    shutil.copy(SPEC.with_name("medication_dispenser.users.toml"), tmp_path)
    return spec


@pytest.fixture
def fault_site(broken_spec: Path) -> str:
    """``FILE:LINE`` of the activity whose condition divides by zero (activity R)."""
    lines = broken_spec.read_text(encoding="utf-8").splitlines()
    line = next(i for i, text in enumerate(lines, 1) if '<Activity Id="R"' in text)
    return f"{broken_spec}:{line}"
