"""Print the requirements of one optional-dependency group of pyproject.toml, one per line
(scripts/test.sh installs the test extras this way when the engine is already compiled)."""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

if __name__ == "__main__":
    group = sys.argv[1] if len(sys.argv) > 1 else "test"
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    for requirement in project["optional-dependencies"][group]:
        print(requirement)
