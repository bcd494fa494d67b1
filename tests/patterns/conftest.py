"""Helpers for the workflow-pattern tests (issue 16): load a spec of ``specs/``, run it, read
the trace. Each test asserts the trace the published pattern definition implies
(van der Aalst, ter Hofstede, Kiepuszewski, Barros 2003, workflowpatterns.com)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

HERE = Path(__file__).resolve().parent
SPECS = HERE / "specs"
ROOT = HERE.parents[1]
CORPUS = ROOT.parent / "shared" / "corpus" / "xpdl"
if not CORPUS.is_dir():
    CORPUS = Path("/work/shared/corpus/xpdl")

sys.path.insert(0, str(HERE))


@pytest.fixture
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not present (expected ../shared/corpus/xpdl beside the checkout)")
    return CORPUS
