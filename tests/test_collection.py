"""Any test folders can be collected together: ``pytest tests/engine tests/patterns`` (or any
other choice of folders) finds every test, with no import error. Each folder's conftest is
imported under the one name ``conftest``, so a test that imported names from its folder's
conftest got another folder's conftest whenever two such folders were collected at once;
what tests share lives in modules of their own (``engine_runs``, ``evaluation_inputs``,
``pattern_paths``, ``walkthrough_inputs``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ["engine", "patterns", "tui", "evaluation", "nothing_lost", "study", "bpmn",
           "evaluation_output"]


def test_the_folders_whose_conftests_clashed_collect_together() -> None:
    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q",
                           "-p", "no:cacheprovider", *(f"tests/{f}" for f in FOLDERS)],
                          capture_output=True, text=True, cwd=ROOT, check=False)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "error" not in done.stdout.splitlines()[-1], done.stdout[-3000:]
