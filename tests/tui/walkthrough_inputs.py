"""The spec and user model the walkthrough tests run (a module of its own, not the conftest:
every test folder's conftest is imported as ``conftest``, so a test that imported names from
it got another folder's when both folders were collected together)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
