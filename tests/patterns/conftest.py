"""Helpers for the workflow-pattern tests (issue 16): load a spec of ``specs/``, run it, read
the trace. Each test asserts the trace the published pattern definition implies
(van der Aalst, ter Hofstede, Kiepuszewski, Barros 2003, workflowpatterns.com)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from pattern_paths import CORPUS  # noqa: E402  (found through the path entry above)


@pytest.fixture
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not present (expected ../shared/corpus/xpdl beside the checkout)")
    return CORPUS
