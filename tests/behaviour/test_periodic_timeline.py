"""``opspec run``'s brief timeline folds the repetitions of periodic workflows.

A robot spec runs its workflows at 5 Hz: an hour printed one line per event was 260,725 lines.
The brief timeline shows each periodic workflow's first instances in full, each step the first
few times it happens (so a new path shows up), then one line per workflow per simulated minute
counting what it folded; deadline misses are always shown. These tests check the folded
timeline against the unfolded one (``--timeline all``) and the trace file of the same seed:
nothing is lost from the counts, and the trace is never shortened.

SISARL-XPDL ``opspec:Rate``/``opspec:Period`` start a workflow instance every period
(docs/sisarl-xpdl.md); ``opspec:Deadline`` is a deadline on each instance.
"""

from __future__ import annotations

import io
import json
import re
from collections import Counter
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands.run_timeline import FULL, BriefTimeline
from opspec.engine.compiled import compile_package
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
_LINE = re.compile(r"^\s+d\d+ \d\d:\d\d:\d\d(\.\d+)?  \S+\s+(?P<where>\S+)\s+(?P<what>.*)$")
_FOLDED = re.compile(r"^\.\.\. (?P<n>[\d,]+) more instances? since [^:]+:\d\d:\d\d(: (?P<steps>.*))?$")


def _run(capsys, spec: Path, *extra: str) -> list[tuple[str, str]]:
    assert main(["run", str(spec), "--seed", "3", *extra]) == 0
    out = capsys.readouterr().out
    return [(m["where"], m["what"]) for m in map(_LINE.match, out.splitlines()) if m]


def _started(lines: list[tuple[str, str]]) -> Counter[str]:
    return Counter(where.split("#")[0] for where, what in lines
                   if "#" in where and what == f"{where.split('#')[0]} started")


def _folded(lines: list[tuple[str, str]]) -> tuple[Counter[str], Counter[tuple[str, str]]]:
    """(instances folded per workflow, times each step was folded) from the folded lines."""
    instances: Counter[str] = Counter()
    steps: Counter[tuple[str, str]] = Counter()
    for where, what in lines:
        m = _FOLDED.match(what)
        if m is None:
            continue
        instances[where] += int(m["n"].replace(",", ""))
        for part in (m["steps"] or "").split(", "):
            if part:
                step, n = part.rsplit(" ", 1)
                steps[(where, step)] += int(n.replace(",", ""))
    return instances, steps


def test_the_folded_timeline_accounts_for_every_instance_and_step(capsys, tmp_path):
    """Every instance and every completed step of the unfolded timeline is either shown or
    counted in a folded line, and the brief timeline is short; the trace file of the same run
    keeps every event."""
    everything = _run(capsys, VACUUM, "--until", "PT3M", "--timeline", "all")
    trace = tmp_path / "run.jsonl"
    brief = _run(capsys, VACUUM, "--until", "PT3M", "--trace", str(trace))
    assert len(brief) < 120 < 10_000 < len(everything)
    folded, folded_steps = _folded(brief)
    started_all, started_brief = _started(everything), _started(brief)
    for process, n in started_all.items():
        assert started_brief[process] + folded[process] == n, process
        assert started_brief[process] == min(n, FULL)      # the first instances in full
    completed_all = Counter((w.split("#")[0], what.removesuffix(" completed"))
                            for w, what in everything if what.endswith(" completed"))
    completed_brief = Counter((w.split("#")[0], what.removesuffix(" completed"))
                              for w, what in brief if what.endswith(" completed"))
    for (process, step), n in folded_steps.items():
        assert completed_brief[(process, step)] + n == completed_all[(process, step)]
        assert completed_brief[(process, step)] == FULL
    # the manoeuvre (a contact: a path not taken every period) is shown when first taken
    assert completed_brief[("manoeuvre", "back_up")] == min(FULL,
                                                           completed_all[("manoeuvre", "back_up")])
    assert completed_all[("manoeuvre", "back_up")] > 0
    kinds = Counter(json.loads(line)["kind"] for line in trace.read_text().splitlines()[1:])
    assert kinds["process.started"] == sum(started_all.values())


def test_deadline_misses_are_never_folded(capsys):
    """One worker with a costly context switch makes ``sense`` miss its 50 ms deadline every
    second: each miss of the unfolded timeline is in the brief one, with its instance."""
    options = ("--until", "PT1M", "--processor-model", "pooled", "--workers", "1",
               "--switch-cost", "0.01")
    everything = _run(capsys, VACUUM, *options, "--timeline", "all")
    brief = _run(capsys, VACUUM, *options)
    misses = [line for line in everything if "deadline of" in line[1]]
    assert len(misses) > 10
    assert [line for line in brief if "deadline of" in line[1]] == misses
    assert all("deadline of sense expired" in what for _w, what in misses)


def test_a_spec_without_periodic_workflows_is_not_folded(capsys):
    """The dispenser's workflows start at times of day, not periodically: nothing folds."""
    main(["run", str(SPEC), "--seed", "3", "--days", "1"])
    out = capsys.readouterr().out
    assert "more instance" not in out and "timeline: brief;" not in out
    assert "notify_workflow#2" in out


def test_folded_lines_per_window_and_at_the_end():
    """Fed by hand: a workflow started every 0.5 s, with 10 s windows: after the first two
    instances, a line per window that had folded instances (none for an empty window), and
    the last, partial window when the run ends."""
    compiled = compile_package(open_spec(VACUUM))
    out = io.StringIO()
    timeline = BriefTimeline(out, compiled, full=2, window=10.0)
    times = [n * 0.5 for n in range(30)] + [35.0, 36.0]        # nothing from 15 s to 35 s
    for n, t in enumerate(times, 1):
        timeline.raw(t, "process.started", "wander", n, None, {"trigger": "period"})
        timeline.raw(t, "activity.completed", "wander", n, "cruise", None)
        timeline.raw(t, "process.completed", "wander", n, None, {})
    timeline.finish(40.0)
    lines = out.getvalue().splitlines()
    assert sum("wander started" in line for line in lines) == 2
    folded = [line for line in lines if "more instance" in line]
    assert [line.split()[1] for line in folded] == ["00:00:10", "00:00:20", "00:00:40"]
    assert [int(re.search(r"\.\.\. (\d+) more", line)[1]) for line in folded] == [18, 10, 2]
    assert timeline.shown == len(lines)


@pytest.mark.parametrize("kind", ["process.terminated", "activity.failed", "fault"])
def test_unusual_events_of_folded_instances_are_shown(kind):
    compiled = compile_package(open_spec(VACUUM))
    out = io.StringIO()
    timeline = BriefTimeline(out, compiled, full=1)
    for n in (1, 2):
        timeline.raw(n * 0.2, "process.started", "sense", n, None, {"trigger": "period"})
    timeline.raw(0.5, kind, "sense", 2, "read_range" if kind.startswith("activity") else None,
                 {"reason": "mode change"})
    assert "sense#2" in out.getvalue().splitlines()[-1]


def test_a_mode_change_is_shown_in_words():
    """The battery workflow's ModeChange (the vacuum cleaner docks when its battery runs
    low) is one of the lines never folded, and says which mode it left and entered."""
    compiled = compile_package(open_spec(VACUUM))
    out = io.StringIO()
    timeline = BriefTimeline(out, compiled, full=0)
    timeline.raw(10.0, "process.started", "battery", 7, None, {"trigger": "period"})
    timeline.raw(10.001, "mode.changed", "battery", 7, "go_dock", {"from": "run", "to": "dock"})
    (line,) = out.getvalue().splitlines()
    assert "battery#7 " in line and line.endswith(" mode run -> dock by go_dock")
