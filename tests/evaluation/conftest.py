from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS_TOML = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture
def evaluate(capsys: pytest.CaptureFixture[str]):
    """``evaluate(*args)`` → (exit status, JSON document or None, stderr)."""

    def run(*args: str) -> tuple[int, dict | None, str]:
        status = main(["evaluate", *args, "--json"])
        captured = capsys.readouterr()
        doc = json.loads(captured.out) if captured.out.strip() else None
        return status, doc, captured.err

    return run


def metrics_of(doc: dict) -> dict:
    """The metrics of an ``--json`` document, without each metric's ``users`` count."""
    return {k: {f: v for f, v in m.items() if f != "users"} for k, m in doc["metrics"].items()}
