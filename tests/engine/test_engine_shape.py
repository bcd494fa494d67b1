"""The engine stays readable and stands on SimPy's public API (issue 27): no module of
opspec/engine over 600 lines, no function over 80 lines, and no reach into SimPy's private
state (opspec/engine/clock.py)."""

from __future__ import annotations

import ast
from pathlib import Path

ENGINE = Path(__file__).resolve().parents[2] / "opspec" / "engine"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80
#: names the engine gives SimPy objects (its clock and events)
SIMPY_OBJECTS = frozenset({"env", "clock", "event", "timeout", "_e", "_event"})


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


def _private_simpy_reads(tree: ast.AST) -> list[tuple[int, str]]:
    """``x._name`` where ``x`` is SimPy's: a clock (``env``, ``clock``, ``self.env``,
    ``state.env``...), an event, or a name imported from simpy; and any ``simpy.x._name``."""
    from_simpy = {"simpy"}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "simpy":
            from_simpy.update(a.asname or a.name for a in node.names)
        if isinstance(node, ast.Import):
            from_simpy.update(a.asname or a.name.split(".")[0] for a in node.names
                              if a.name.split(".")[0] == "simpy")
    found = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                and not node.attr.startswith("__")):
            continue
        base = node.value
        names = []
        while isinstance(base, ast.Attribute):
            names.append(base.attr)
            base = base.value
        if isinstance(base, ast.Name):
            names.append(base.id)
        if names and (names[0] in SIMPY_OBJECTS or names[-1] in from_simpy):
            found.append((node.lineno, ".".join(reversed(names)) + "." + node.attr))
    return found


def test_the_check_for_private_simpy_reads_finds_them() -> None:
    """The check below finds what issue 27 counted (38 reads of ``env._now``, ``_queue``,
    ``_eid``) and leaves the engine's own private attributes alone."""
    code = ("import simpy\nfrom simpy.core import Environment as E\n"
            "a = self.env._now\nb = state.env._queue\nc = simpy.core._x\nd = E._eid\n"
            "e = event._value\nf = self._ready\ng = sim.env.now\n")
    assert [what for _, what in _private_simpy_reads(ast.parse(code))] == [
        "self.env._now", "state.env._queue", "simpy.core._x", "E._eid", "event._value"]


def test_the_engine_uses_only_simpys_public_api() -> None:
    """Issue 27: the engine stands on SimPy's public API (``env.now``, ``env.timeout``,
    ``env.peek``, ``env.step``, ``env.run``), never on its private state."""
    reach = [f"{path.name}:{line} {what}" for path in _modules()
             for line, what in _private_simpy_reads(ast.parse(path.read_text(encoding="utf-8")))]
    assert reach == [], f"the engine reads SimPy's private state: {reach}"
