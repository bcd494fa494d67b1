"""From a fresh virtual environment, the README's first command's kind of install (opspec
alone, no extras) gives a working spec-test setup: `opspec new NAME` writes a project whose
tests pass right away. Slow (a whole install, a few minutes): run with ``-m slow``."""

from __future__ import annotations

import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_a_new_project_passes_its_tests_in_a_fresh_venv(tmp_path: Path) -> None:
    """One fresh venv, one install, then a project of each template in a folder of its own
    (the install is the slow part: one for both templates instead of one each).

    What is checked is the installed package: opspec from a (non-editable) build of this
    checkout with only the dependencies it declares, its templates and its pytest plugin. So
    the build runs without isolation (setuptools and wheel installed first): an isolated
    build installs the build requirements, mypy and numpy among them, that only compiling
    the engine needs, and nothing is compiled here (OPSPEC_PURE_PYTHON) -- the isolated,
    compiling build is what scripts/test.sh's own install does. pip does not byte-compile
    what it installs (Python compiles the few modules the projects' tests import), and the
    venv gets no pip of its own (the running one installs into it). Together about a third
    of the install's CPU."""
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)    # the running pip installs into it (--python)
    python = env_dir / "bin" / "python"
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTEST_", "TEXTUAL_", "VIRTUAL_ENV"))}
    env["OPSPEC_PURE_PYTHON"] = "1"
    pip = [sys.executable, "-m", "pip", "--python", str(python), "install", "-q",
           "--no-compile"]
    subprocess.run([*pip, "setuptools>=68", "wheel"], env=env, check=True, timeout=600,
                   capture_output=True)
    subprocess.run([*pip, "--no-build-isolation", str(ROOT)], env=env, check=True,
                   timeout=1200, capture_output=True)
    for template in ("pill", "stove"):
        folder = tmp_path / template
        folder.mkdir()
        subprocess.run([str(env_dir / "bin" / "opspec"), "new", "mine", "--template", template],
                       cwd=folder, env=env, check=True, timeout=120, capture_output=True)
        done = subprocess.run([str(python), "-m", "pytest", "-q", "-p", "no:cacheprovider"],
                              cwd=folder / "mine", env=env, capture_output=True, text=True,
                              timeout=600, check=False)
        assert done.returncode == 0, (template, done.stdout + done.stderr)
        assert "3 passed" in done.stdout, template
        assert sys.executable not in done.stdout, template
