"""Golden traces: compare a run with a stored, normalised trace and fail with a readable diff.

::

    def test_prompt_user_day(spec, simulate, golden):      # the plugin's fixture
        golden(simulate(spec, script=[("after trg_2 90s", "press_report")]),
               "golden/prompt_user_day.jsonl")

    compare(result, "tests/golden/day.jsonl")                # or directly; regen=True writes

``pytest --opspec-regen-golden`` (or ``regen=True``) writes the file instead of comparing.

The stored form is JSON Lines: a header line
``{"format": "opspec-golden-trace", "version": 1, "package": ..., "replications": n}``, then
one line per event with the keys ``time, kind, process, instance, activity, lane,
participant, data`` (absent ones omitted; ``data`` keys sorted; times rounded to the
microsecond) and ``replication`` first when there are several. ``seq``, ``package`` and any
``wall`` (wall-clock) value are left out by default (``ignore=``): a line then depends only on
what happened, so one added event shows as one added line, not a renumbered file. A seeded
run gives the same lines on every machine.
"""

from __future__ import annotations

import difflib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from opspec.engine.trace import TraceEvent

__all__ = ["DEFAULT_IGNORE", "GOLDEN_FORMAT", "compare", "compare_golden", "normalise"]

GOLDEN_FORMAT = "opspec-golden-trace"
GOLDEN_VERSION = 1
DEFAULT_IGNORE = ("seq", "package", "wall")
_KEYS = ("time", "kind", "process", "instance", "activity", "lane", "participant")


def _traces(run: Any) -> tuple[list[Sequence[TraceEvent]], str | None]:
    from opspec.engine.simulation import RunResult

    if isinstance(run, RunResult):
        if run.trace is None:
            raise ValueError("this run kept no trace: run it with keep_trace=True")
        return [run.trace], None
    if hasattr(run, "traces") and hasattr(run, "runs"):        # a SimulationResult
        return list(run.traces), getattr(getattr(run, "spec", None), "id", None)
    if isinstance(run, Sequence) and all(isinstance(e, TraceEvent) for e in run):
        return [run], None
    raise TypeError("golden traces compare a SimulationResult, a RunResult or a sequence of "
                    f"TraceEvent, not {type(run).__name__}")


def _clean(value: Any, ignore: frozenset[str]) -> Any:
    if isinstance(value, dict):
        return {str(k): _clean(v, ignore) for k, v in sorted(value.items(), key=lambda kv:
                                                               str(kv[0]))
                if str(k) not in ignore}
    if isinstance(value, (list, tuple)):
        return [_clean(v, ignore) for v in value]
    if isinstance(value, float):
        return round(value, 6)
    return value


def _line(event: TraceEvent, replication: int | None, ignore: frozenset[str]) -> str:
    obj: dict[str, Any] = {}
    if replication is not None:
        obj["replication"] = replication
    for key in _KEYS:
        value = getattr(event, key)
        if value is not None and key not in ignore:
            obj[key] = round(float(value), 6) if key == "time" else value
    if "seq" not in ignore:
        obj["seq"] = event.seq
    if "package" not in ignore and event.package is not None:
        obj["package"] = event.package
    data = _clean(dict(event.data), ignore) if "data" not in ignore else {}
    if data:
        obj["data"] = data
    return json.dumps(obj, ensure_ascii=False, default=str)


def normalise(run: Any, *, ignore: Sequence[str] = DEFAULT_IGNORE) -> list[str]:
    """The golden lines of ``run`` (a SimulationResult, RunResult or list of events):
    the header, then one line per event."""
    traces, package = _traces(run)
    skip = frozenset(ignore)
    if package is None:
        package = next((e.package for t in traces for e in t if e.package), None)
    header = {"format": GOLDEN_FORMAT, "version": GOLDEN_VERSION, "package": package,
              "replications": len(traces)}
    lines = [json.dumps(header)]
    many = len(traces) > 1
    for r, trace in enumerate(traces):
        lines.extend(_line(e, r if many else None, skip) for e in trace)
    return lines


def _summary(stored: list[str], now: list[str]) -> tuple[int, int, int | None]:
    """(lines only stored, lines only now, index of the first differing line)."""
    missing = extra = 0
    first: int | None = None
    matcher = difflib.SequenceMatcher(a=stored, b=now, autojunk=False)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "equal":
            continue
        first = i1 if first is None else first
        missing += i2 - i1
        extra += j2 - j1
    return missing, extra, first


def compare(run: Any, path: str | Path, *, regen: bool = False,
            ignore: Sequence[str] = DEFAULT_IGNORE, context: int = 3,
            max_diff_lines: int = 60) -> Path | None:
    """Compare ``run`` with the golden trace at ``path``; with ``regen`` write it instead
    (returning the path written). ``AssertionError`` when they differ, with the counts of
    missing and extra events and a unified diff of the first differences (``context`` lines
    around each, at most ``max_diff_lines`` lines), or when the file does not exist."""
    __tracebackhide__ = True
    target = Path(path)
    now = normalise(run, ignore=ignore)
    if regen:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text("\n".join(now) + "\n", encoding="utf-8")
        return target
    if not target.exists():
        raise AssertionError(f"no golden trace at {target}: run pytest with "
                             "--opspec-regen-golden (or compare(..., regen=True)) to write "
                             "it, then review and commit the file")
    stored = target.read_text(encoding="utf-8").splitlines()
    if stored == now:
        return None
    missing, extra, first = _summary(stored, now)
    diff = list(difflib.unified_diff(stored, now, fromfile=f"{target} (golden)",
                                     tofile="this run", n=context, lineterm=""))
    shown = diff[:max_diff_lines]
    if len(diff) > max_diff_lines:
        shown.append(f"... {len(diff) - max_diff_lines} more diff line(s)")
    where = ""
    if first is not None and 0 < first < len(stored):
        try:
            when = json.loads(stored[first]).get("time")
        except ValueError:
            when = None
        where = f"; first difference at event {first}" + (
            f" (time {when:g} s)" if isinstance(when, (int, float)) else "")
    head = (f"the run differs from the golden trace {target}: {len(stored) - 1} event(s) "
            f"stored, {len(now) - 1} now; {missing} line(s) missing from this run, "
            f"{extra} extra{where}")
    hint = ("if the change is intended, rerun with --opspec-regen-golden and review the "
            "file's diff before committing it")
    raise AssertionError("\n".join([head, *shown, hint]))


def compare_golden(run: Any, path: str | Path, *, regenerate: bool = False,
                   **options: Any) -> Path | None:
    """:func:`compare` with the plugin's spelling (``regenerate``)."""
    __tracebackhide__ = True
    return compare(run, path, regen=regenerate, **options)
