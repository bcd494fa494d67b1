"""Print requirements of pyproject.toml, one per line: those of each optional-dependency group
named (`test`), and with `--dependencies` first opspec's own. scripts/test.sh installs them
this way: the test extras alone when the engine is already compiled, and on a fresh clone
everything but opspec itself, beside the compile of the engine."""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

if __name__ == "__main__":
    arguments = sys.argv[1:] or ["test"]
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    requirements: list[str] = []
    for argument in arguments:
        if argument == "--dependencies":
            requirements += project["dependencies"]
        else:
            requirements += project["optional-dependencies"][argument]
    for requirement in requirements:
        print(requirement)
