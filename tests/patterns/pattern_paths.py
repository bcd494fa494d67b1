"""Where the workflow-pattern tests find their specs and the shared XPDL corpus (a module of its
own, not the conftest: every test folder's conftest is imported as ``conftest``, so a test
that imported names from it got another folder's when both folders were collected together)."""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent
SPECS = HERE / "specs"
ROOT = HERE.parents[1]
CORPUS = ROOT.parent / "shared" / "corpus" / "xpdl"
if not CORPUS.is_dir():
    CORPUS = Path("/work/shared/corpus/xpdl")
