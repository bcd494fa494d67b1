"""The study protocol the tests share: three participants, two variants of the dispenser
(re-alarm after 300 s, or after 30 s)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture
def protocol_file(tmp_path: Path) -> Path:
    quick = tmp_path / "dispenser-30s.xpdl"
    quick.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT30S"),
                     encoding="utf-8")
    shutil.copy(SPEC.with_name("medication_dispenser.users.toml"),
                tmp_path / "dispenser-30s.users.toml")
    protocol = tmp_path / "study.toml"
    protocol.write_text(f"""
[study]
name = "re-alarm after 5 minutes or 30 seconds"
days = 1
seed = 4
recordings = "rec"
participants = ["P01", "P02", "P03"]

[[variants]]
id = "A"
spec = "{SPEC}"
told = "Variant A: the dispenser rings when a dose is due. Take your pills as at home."

[[variants]]
id = "B"
spec = "dispenser-30s.xpdl"
told = "Variant B: the same dispenser; it may ring again sooner."
""", encoding="utf-8")
    return protocol
