"""The spec and user model the evaluation tests evaluate, and how they read a ``--json``
document's metrics (a module of its own, not the conftest: every test folder's conftest is
imported as ``conftest``, so a test that imported names from it got another folder's when
both folders were collected together)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS_TOML = ROOT / "specs" / "medication_dispenser.users.toml"


def metrics_of(doc: dict) -> dict:
    """The metrics of an ``--json`` document, without each metric's ``users`` count."""
    return {k: {f: v for f, v in m.items() if f != "users"} for k, m in doc["metrics"].items()}
