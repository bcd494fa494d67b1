"""One property language (issue 18): a monitor watched online and a predicate judged offline on
the stored trace give the same verdict and the same witness; and hand-built traces whose verdict
is known from the property's definition (Dwyer, Avrunin & Corbett's specification patterns, read
over a finite trace; metric bounds as in MTL), boundary cases included."""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import math
import shutil
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape

import numpy as np
import pytest

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.names import spec_names
from opspec.engine.trace import TraceEvent
from opspec.engine.trace_sinks import read_trace
from opspec.properties.language import MonitorResult, trace_end
from opspec.properties.text_form import parse_property
from opspec.testing.expectations import expect, parse_expectation
from opspec.testing.monitors import min_gap
from opspec.testing.predicates import check, failures, happens_before, holds, within
from opspec.testing.simulation import load_spec_file, simulate

from .conftest import DISPENSER, USERS

# Each kind of property, on the dispenser with its reference users over two days: some hold,
# some are broken many times (a 2 min response, 9 alarms), some a few times (the 4 h gap).
PROPERTIES = [
    "bounded_response sound_alarm dispense 2min",            # response within a bound
    "dispense within 15 min after sound_alarm",               # the same, as a then line says it
    "response sound_alarm dispense|record_missed",            # unbounded response
    "never notify_caregiver",                                 # absence
    "never press_report",                                     # (broken at every dose)
    "eventually record_missed",                               # existence
    "min_gap dispense 4h",                                    # minimum gap
    "never dispense twice within 3h45m",
    "max_count sound_alarm 3 per 6h",                         # at most N in a window
    "count sound_alarm <= 8",                                 # count bounds over the run
    "count dispense in [7, 8]",
    "count trg_2 >= 9",
    "press_report before each dispense",                      # precedence
    "dispense before sound_alarm",
    "never_while dispense after record_missed until sound_alarm",
]
SEEDS = (1, 2, 3)


def _spec_with_monitors(tmp_path: Path, monitors: list[str]) -> Path:
    """The dispenser declaring ``monitors`` (opspec:Monitor, one per line), with its users."""
    text = DISPENSER.read_text(encoding="utf-8")
    anchor = '<ExtendedAttribute Name="opspec:Metrics">'
    assert anchor in text
    block = "\n      ".join(escape(m) for m in monitors)          # '<=' is '&lt;=' in XML
    path = tmp_path / "dispenser.xpdl"
    path.write_text(text.replace(anchor, f'<ExtendedAttribute Name="opspec:Monitor">\n      '
                                         f'{block}\n    </ExtendedAttribute>\n    {anchor}', 1),
                    encoding="utf-8")
    shutil.copy(USERS, tmp_path / "dispenser.users.toml")
    return path


def _ids(events: Any) -> list[tuple[int, float, str, str | None]]:
    return [(e.seq, e.time, e.kind, e.activity) for e in events]


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[int, tuple[dict[str, Any], Path]]:
    """``opspec run --seed S --days 2 --trace FILE --json`` of the monitored dispenser: its
    JSON (the monitors' online verdicts) and the stored trace, per seed."""
    folder = tmp_path_factory.mktemp("runs")
    spec = _spec_with_monitors(folder, PROPERTIES)
    out: dict[int, tuple[dict[str, Any], Path]] = {}
    for seed in SEEDS:
        trace = folder / f"seed{seed}.jsonl"
        buffer = io.StringIO()
        with contextlib.redirect_stdout(buffer):
            status = main(["run", str(spec), "--seed", str(seed), "--days", "2",
                           "--trace", str(trace), "--json"])
        assert status == 0
        out[seed] = (json.loads(buffer.getvalue()), trace)
    return out


@pytest.fixture(scope="module")
def names() -> Any:
    return spec_names(compile_package(load_spec_file(DISPENSER)))


@pytest.mark.parametrize("seed", SEEDS)
def test_opspec_run_monitors_and_predicates_on_the_stored_trace_agree(
        runs: dict[int, tuple[dict[str, Any], Path]], names: Any, seed: int) -> None:
    doc, path = runs[seed]
    events = list(read_trace(path))
    assert events[-1].kind == "run.ended" and trace_end(events) == 2 * 86_400.0
    for text in PROPERTIES:
        online = doc["monitors"][text]
        offline = parse_property(text).bind(names).judge(events)
        assert offline.count == online["violations"], text
        assert [(v.time, v.message, [e.seq for e in v.events])
                for v in offline.violations[:5]] == [
            (v["time"], v["message"], v["events"]) for v in online["first"]], text
        # the predicate of the same text on the stored file: same verdict, first witness marked
        found = failures(path, text, spec=DISPENSER)
        assert bool(found) == bool(online["violations"]), text
        if found:
            first = online["first"][0]
            assert f"  but {first['message']}" in found[0]
            by_seq = {e.seq: e for e in events}
            marked = [line for line in found[0].splitlines() if line.startswith(">")]
            assert len(marked) == len(first["events"]), text
            for line, seq in zip(marked, first["events"], strict=True):
                assert by_seq[seq].kind in line and (by_seq[seq].activity or "") in line


def test_the_runs_break_and_keep_properties_of_every_kind(
        runs: dict[int, tuple[dict[str, Any], Path]]) -> None:
    """The comparison above is not vacuous: across the seeds each kind is both broken and
    kept somewhere, or broken in every run (so verdicts and witnesses were compared)."""
    broken = {text: sum(1 for doc, _ in runs.values() if doc["monitors"][text]["violations"])
              for text in PROPERTIES}
    for text in ("bounded_response sound_alarm dispense 2min", "count sound_alarm <= 8",
                 "dispense before sound_alarm", "eventually record_missed",
                 "max_count sound_alarm 3 per 6h", "min_gap dispense 4h", "never press_report",
                 "count trg_2 >= 9"):
        assert broken[text] >= 1, text
    for text in ("press_report before each dispense", "never notify_caregiver",
                 "dispense within 15 min after sound_alarm", "count dispense in [7, 8]"):
        assert broken[text] < len(SEEDS), text


@pytest.mark.parametrize("seed", SEEDS[:2])
def test_the_python_api_run_gives_the_monitor_and_the_stored_trace_the_same_witness_events(
        tmp_path: Path, seed: int) -> None:
    import opspec
    from opspec.engine.trace_sinks import JsonlSink

    spec = _spec_with_monitors(tmp_path, PROPERTIES)
    with JsonlSink(tmp_path / "t.jsonl", {"seed": seed}) as sink:
        outcome = opspec.run(spec, seed=seed, days=2, listeners=[sink])
    stored = list(read_trace(tmp_path / "t.jsonl"))
    loaded = opspec.runs.load(spec)
    for monitor, online in zip(loaded.monitors, outcome.monitors, strict=True):
        offline: MonitorResult = monitor.judge(stored)
        assert (offline.monitor, offline.count) == (online.monitor, online.count)
        assert [(v.time, v.message, _ids(v.events)) for v in offline.violations] == [
            (v.time, v.message, _ids(v.events)) for v in online.violations]
        assert _ids(offline.open) == _ids(online.open)


def test_a_monitor_a_predicate_and_a_then_line_with_the_same_text_agree(
        dispenser: Any) -> None:
    texts = ["bounded_response sound_alarm dispense 2min", "min_gap dispense 4h",
             "count sound_alarm <= 4", "press_report before dispense", "never notify_caregiver"]
    result = simulate(dispenser, users=3, days=1, user_model=USERS, seed=5, monitors=texts)
    report = result.monitor_report()
    for text in texts:
        row = report.row(text)
        assert holds(result, text) == (row.violations == 0)
        with_then = parse_expectation(text).check(result)
        assert (with_then is None) == (row.violations == 0)
        if row.violations:
            first = row.first[0]
            assert first.message in with_then  # type: ignore[operator]
            assert first.message in failures(result, text)[0]
    # the Python spellings are the same properties
    assert holds(result, within("sound_alarm", "dispense", 120)) == holds(
        result, "bounded_response sound_alarm dispense 2min")
    assert holds(result, min_gap("dispense", hours=4)) == (
        report.row("min_gap dispense 4h").violations == 0)
    check(result, happens_before("press_report", "dispense", each=True))
    expect(result, "press_report before each dispense", "activity press_report before "
           "activity dispense", "never activity dispense twice within 3h45m")


# ---------------------------------------------------------------- hand-built traces
def _trace(*steps: tuple[float, str]) -> list[TraceEvent]:
    """Completions of the named activities at the given times, in this order (seq 1, 2...)."""
    return [TraceEvent(t, "activity.completed", "p", 1, name, seq=i)
            for i, (t, name) in enumerate(steps, 1)]


def _judge(text: str, steps: list[tuple[float, str]], end: float) -> MonitorResult:
    """The verdict online (events fed one by one to the listener) - checked against the
    offline predicate on the same events."""
    prop = parse_property(text)
    events = _trace(*steps)
    run = prop.start()
    for event in events:
        run(event)
    run.finish(end)
    online = run.result()
    offline = prop.judge(events, end)
    assert (online.count, online.violations, online.open) == (
        offline.count, offline.violations, offline.open)
    predicate_fails = failures(events + [TraceEvent(end, "run.ended", seq=len(events) + 1)],
                               text)
    assert bool(predicate_fails) == bool(online.count)
    return online


def _witness(result: MonitorResult) -> list[list[tuple[float, str | None]]]:
    return [[(e.time, e.activity) for e in v.events] for v in result.violations]


# (property, trace, end of run, violation times, witnesses (time, activity) per violation,
#  obligations left open)
DWYER: dict[str, tuple[str, list[tuple[float, str]], float, list[float],
                       list[list[tuple[float, str]]], int]] = {
    # absence: globally never P
    "absence-holds": ("never p", [(1, "q"), (2, "q")], 10, [], [], 0),
    "absence-each-occurrence": ("never p", [(1, "p"), (2, "q"), (3, "p")], 10, [1, 3],
                                [[(1, "p")], [(3, "p")]], 0),
    # existence: P at least once (decided at the end; the run is the whole time it talks of)
    "existence-holds": ("eventually p", [(1, "q"), (9.5, "p")], 10, [], [], 0),
    "existence-empty-trace": ("eventually p", [], 10, [10], [[]], 0),
    # precedence: S precedes P (no P before the first S; P need not happen)
    "precedence-no-p": ("s before p", [(1, "q")], 10, [], [], 0),
    "precedence-holds": ("s before p", [(1, "s"), (2, "p"), (3, "p")], 10, [], [], 0),
    "precedence-p-first": ("s before p", [(1, "p"), (2, "s"), (3, "p")], 10, [1],
                           [[(1, "p")]], 0),
    "precedence-same-instant-s-first": ("s before p", [(5, "s"), (5, "p")], 10, [], [], 0),
    "precedence-same-instant-p-first": ("s before p", [(5, "p"), (5, "s")], 10, [5],
                                        [[(5, "p")]], 0),
    "precedence-event-that-is-both": ("s|b before p|b", [(1, "b")], 10, [], [], 0),
    "precedence-each": ("s before each p", [(1, "s"), (2, "p"), (3, "p"), (4, "s"), (5, "p")],
                        10, [3], [[(1, "s"), (3, "p")]], 0),
    # response: S responds to P before the end of the run (a P still waiting at the end is
    # a violation: the claim is about the run)
    "response-holds": ("response p s", [(1, "p"), (7, "s")], 10, [], [], 0),
    "response-unanswered-at-end": ("response p s", [(1, "p"), (2, "s"), (3, "p")], 10, [10],
                                   [[(3, "p")]], 0),
    # bounded response: S within d of P (inclusive bound)
    "bounded-exactly-at-the-bound": ("bounded_response p s 10s", [(0, "p"), (10, "s")], 50,
                                     [], [], 0),
    "bounded-just-late": ("bounded_response p s 10s", [(0, "p"), (10.001, "s")], 50, [10],
                          [[(0, "p"), (10.001, "s")]], 0),
    "bounded-one-s-answers-all-pending": ("bounded_response p s 10s",
                                          [(0, "p"), (4, "p"), (9, "s")], 50, [], [], 0),
    "bounded-s-before-p-same-instant": ("bounded_response p s 10s", [(0, "s"), (0, "p")], 50,
                                        [10], [[(0, "p")]], 0),
    "bounded-s-after-p-same-instant": ("bounded_response p s 10s", [(0, "p"), (0, "s")], 50,
                                       [], [], 0),
    "bounded-event-that-is-both": ("bounded_response p|b s|b 10s", [(0, "b")], 50, [], [], 0),
    "bounded-open-at-the-end": ("bounded_response p s 10s", [(45, "p")], 50, [], [], 1),
    "bounded-due-exactly-at-the-end": ("bounded_response p s 10s", [(40, "p")], 50, [], [], 1),
    "bounded-due-just-before-the-end": ("bounded_response p s 10s", [(39.9, "p")], 50,
                                        [49.9], [[(39.9, "p")]], 0),
    # absence after Q until R (Dwyer's scope; the window stays open without an R)
    "between-inside": ("never_while p after q until r", [(1, "q"), (2, "p"), (3, "r")], 10,
                       [2], [[(1, "q"), (2, "p")]], 0),
    "between-outside": ("never_while p after q until r",
                        [(1, "p"), (2, "q"), (3, "r"), (4, "p")], 10, [], [], 0),
    "between-no-r-until-the-end": ("never_while p after q until r", [(1, "q"), (9, "p")], 10,
                                   [9], [[(1, "q"), (9, "p")]], 0),
    "between-p-is-the-closing-r": ("never_while p|b after q until r|b", [(1, "q"), (2, "b")],
                                   10, [], [], 0),
    "between-p-is-the-opening-q": ("never_while p|b after q|b until r", [(1, "b")], 10, [1],
                                   [[(1, "b")]], 0),
    # minimum gap: exactly the gap apart is allowed; simultaneous events are 0 s apart
    "gap-exactly": ("min_gap a 10s", [(0, "a"), (10, "a"), (20, "a")], 30, [], [], 0),
    "gap-simultaneous": ("min_gap a 10s", [(0, "a"), (0, "a")], 30, [0],
                         [[(0, "a"), (0, "a")]], 0),
    # counts: an upper bound breaks at the occurrence too many, a lower one at the end
    "count-upper": ("count a <= 2", [(1, "a"), (2, "a"), (3, "a"), (4, "a")], 10, [3],
                    [[(1, "a"), (2, "a"), (3, "a"), (4, "a")]], 0),
    "count-lower": ("count a >= 2", [(1, "a")], 10, [10], [[(1, "a")]], 0),
    "count-range-holds": ("count a in [1, 2]", [(1, "a"), (5, "a")], 10, [], [], 0),
    # a window is half-open: at 10 s the event at 0 s has left it, those at 5 and 9.9 have not
    "count-window": ("max_count a 2 per 10s", [(0, "a"), (5, "a"), (9.9, "a"), (10, "a")], 20,
                     [9.9, 10], [[(0, "a"), (5, "a"), (9.9, "a")],
                                 [(5, "a"), (9.9, "a"), (10, "a")]], 0),
    "count-window-exactly-apart": ("max_count a 1 per 10s", [(0, "a"), (10, "a"), (20, "a")],
                                   30, [], [], 0),
}


@pytest.mark.parametrize("case", list(DWYER), ids=list(DWYER))
def test_hand_built_traces_get_the_verdict_of_the_definition(case: str) -> None:
    text, steps, end, times, witnesses, open_ = DWYER[case]
    result = _judge(text, steps, end)
    assert [v.time for v in result.violations] == pytest.approx(times)
    assert _witness(result) == [[(t, a) for t, a in w] for w in witnesses]
    assert len(result.open) == open_


# ---------------------------------------------------------------- random traces vs formulas
def _random_trace(rng: np.random.Generator) -> tuple[list[TraceEvent], float]:
    n = int(rng.integers(0, 25))
    times = np.sort(np.round(rng.uniform(0, 100, n)))       # whole seconds: ties and bounds
    names = rng.choice(["p", "s", "q", "r", "x"], n)
    events = _trace(*zip(times.tolist(), names.tolist(), strict=True))
    return events, float(rng.choice([100.0, times[-1] if n else 0.0]))


def _bounded_response_formula(events: list[TraceEvent], d: float, end: float) -> list[int]:
    """MTL: G(p -> F[0,d] s) judged where the run covers the window (t + d < end)."""
    return [e.seq for i, e in enumerate(events) if e.activity == "p" and e.time + d < end
            and not any(f.activity == "s" and f.time <= e.time + d for f in events[i:])]


def _precedence_formula(events: list[TraceEvent]) -> list[int]:
    """!p W s: the p before the first s."""
    first = next((e.seq for e in events if e.activity == "s"), math.inf)
    return [e.seq for e in events if e.activity == "p" and e.seq < first]


def _between_formula(events: list[TraceEvent]) -> list[int]:
    """G(q & !r -> (!p W r)): p with a q since the last r (or since the start)."""
    out, opened = [], False
    for e in events:
        opened = (opened or e.activity == "q") and e.activity != "r"
        if opened and e.activity == "p":
            out.append(e.seq)
    return out


def _gap_formula(events: list[TraceEvent], d: float) -> list[int]:
    ps = [e for e in events if e.activity == "p"]
    return [b.seq for a, b in itertools.pairwise(ps) if b.time - a.time < d]


def test_random_traces_get_the_verdicts_of_the_formulas() -> None:
    rng = np.random.default_rng(20240518)
    for _ in range(400):
        events, end = _random_trace(rng)
        d = float(rng.choice([0.0, 5.0, 10.0, 30.0]))
        response = parse_property(f"bounded_response p s {d:g}s").judge(events, end)
        assert [v.events[0].seq for v in response.violations] == _bounded_response_formula(
            events, d, end)
        precedence = parse_property("s before p").judge(events, end)
        assert [v.events[-1].seq for v in precedence.violations] == _precedence_formula(events)
        between = parse_property("never_while p after q until r").judge(events, end)
        assert [v.events[-1].seq for v in between.violations] == _between_formula(events)
        if d > 0:
            gap = parse_property(f"min_gap p {d:g}s").judge(events, end)
            assert [v.events[-1].seq for v in gap.violations] == _gap_formula(events, d)
            window = parse_property(f"max_count p 1 per {d:g}s").judge(events, end)
            assert [v.time for v in window.violations] == [v.time for v in gap.violations]


# ---------------------------------------------------------------- one language, every door
@pytest.mark.parametrize("then_line, monitor_line", [
    ("never activity dispense twice within 3h45m", "min_gap activity:dispense 3h45m"),
    ("activity dispense within 300s after activity sound_alarm",
     "bounded_response activity:sound_alarm activity:dispense 5 min"),
    ("activity press_report before activity dispense", "press_report before dispense"),
    ("never activity notify_caregiver", "never activity:notify_caregiver"),
    ("count activity sound_alarm == 3", "count sound_alarm == 3"),
], ids=["gap", "response", "precedence", "absence", "count"])
def test_every_spelling_reads_as_the_same_property(then_line: str, monitor_line: str,
                                                  names: Any) -> None:
    from dataclasses import replace

    a = parse_expectation(then_line).property
    b = parse_property(monitor_line, what="monitor")
    assert a is not None
    assert replace(a.bind(names), text="") == replace(b.bind(names), text="")


def test_a_stored_trace_is_judged_by_its_path(tmp_path: Path) -> None:
    spec = _spec_with_monitors(tmp_path, ["never notify_caregiver"])
    trace = tmp_path / "t.jsonl"
    steps = tmp_path / "absent.toml"
    steps.write_text('steps = [["never", "press_report"]]\n', encoding="utf-8")
    assert main(["run", str(spec), "--until", "09:00", "--script", str(steps),
                 "--trace", str(trace), "--timeline", "none"]) == 0
    assert not holds(trace, "never notify_caregiver")
    assert holds(trace, "notify_caregiver within 15 min after process:notify_workflow")
    with pytest.raises(AssertionError, match=r"(?s)notify_caregiver happened at d1 08:15:"
                                             r"00.*>.*activity.completed +notify_caregiver"):
        check(trace, "never notify_caregiver")


def test_several_monitor_attributes_all_count_and_validate_without_a_warning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = DISPENSER.read_text(encoding="utf-8").replace(
        '<ExtendedAttribute Name="opspec:Metrics">',
        '<ExtendedAttribute Name="opspec:Monitor" Value="min_gap dispense 4h"/>\n'
        '    <ExtendedAttribute Name="opspec:Monitor" Value="count sound_alarm &lt;= 3"/>\n'
        '    <ExtendedAttribute Name="opspec:Metrics">', 1)
    spec = tmp_path / "two.xpdl"
    spec.write_text(text, encoding="utf-8")
    assert main(["validate", str(spec)]) == 0
    assert "0 warnings" in capsys.readouterr().out
    assert main(["run", str(spec), "--until", "13:00", "--json"]) == 0
    monitors = json.loads(capsys.readouterr().out)["monitors"]
    assert list(monitors) == ["min_gap dispense 4h", "count sound_alarm <= 3"]
    # nobody reports: three alarms at 08:00, three at 12:00, the 4th is the one too many
    (first,) = monitors["count sound_alarm <= 3"]["first"]
    assert first["time"] == 12 * 3600 and "happened 6 time(s)" in first["message"]
