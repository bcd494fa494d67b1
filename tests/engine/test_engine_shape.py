"""The engine stays readable and stands on its own clock (issue 27): no module of
opspec/engine over 600 lines, no function over 80 lines, and no reach into SimPy's private
state (the engine owns its event heap: opspec/engine/clock.py)."""

from __future__ import annotations

import ast
from pathlib import Path

ENGINE = Path(__file__).resolve().parents[2] / "opspec" / "engine"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80
SIMPY_PRIVATE = frozenset({"_now", "_queue", "_eid", "_active_proc"})


def _modules() -> list[Path]:
    found = sorted(ENGINE.rglob("*.py"))
    assert len(found) > 20, "the engine's modules were not found"
    return found


def test_no_engine_module_is_over_600_lines() -> None:
    long = {p.name: n for p in _modules()
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert long == {}, f"split these modules by concept: {long}"


def test_no_engine_function_is_over_80_lines() -> None:
    long = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = (node.end_lineno or node.lineno) - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"{path.name}:{node.lineno} {node.name} ({lines} lines)")
    assert long == [], f"split these functions: {long}"


def test_the_engine_reads_no_private_simpy_state_and_schedules_on_its_own_clock() -> None:
    reach = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr in SIMPY_PRIVATE:
                reach.append(f"{path.name}:{node.lineno} .{node.attr}")
            if isinstance(node, ast.Import | ast.ImportFrom):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [
                    node.module or ""]
                if any(n == "simpy" or n.startswith("simpy.") for n in names):
                    reach.append(f"{path.name}:{node.lineno} imports SimPy")
    assert reach == [], f"the engine runs on opspec.engine.clock, not SimPy's internals: {reach}"
