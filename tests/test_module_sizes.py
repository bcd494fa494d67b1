"""Small modules with one job each: no module of the opspec package is over 600 lines (the
engine's own, stricter shape is tests/engine/test_engine_shape.py). A module past the limit is
split by concept (what its parts are about), not cut at a line count."""

from __future__ import annotations

from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "opspec"
MAX_MODULE_LINES = 600


def test_no_module_of_the_package_is_over_600_lines() -> None:
    modules = sorted(PACKAGE.rglob("*.py"))
    assert len(modules) > 100, "the package's modules were not found"
    long = {str(p.relative_to(PACKAGE)): n for p in modules
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert long == {}, f"split these modules by concept: {long}"
