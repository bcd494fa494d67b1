"""`opspec walkthrough SPEC < /dev/null` refuses at once (exit 2) instead of waiting for keys
that never come, and says what to do instead; nothing is recorded."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_without_a_terminal_the_walkthrough_refuses_at_once(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "TEXTUAL_"))}
    done = subprocess.run([sys.executable, "-m", "opspec", "walkthrough", str(SPEC)],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          cwd=tmp_path, env=env, timeout=120, check=False)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.startswith("opspec walkthrough: the walkthrough needs a terminal")
    assert "standard input is not one" in done.stderr and "--script FILE" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "walkthroughs").exists()
