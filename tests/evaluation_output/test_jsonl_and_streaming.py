"""traces.jsonl in the opspec trace format, and both exporters' flat memory at scale."""

from __future__ import annotations

import json
import tracemalloc
from collections.abc import Iterator
from pathlib import Path

import pytest

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, EventKind, TraceEvent
from opspec.engine.trace_sinks import read_trace, read_trace_header
from opspec.errors import EvaluationError
from opspec.evaluation.exporters import JsonlTraceWriter, XesWriter


def test_jsonl_export_is_a_trace_file_with_a_case_on_every_event(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    path = tmp_path / "traces.jsonl"
    with JsonlTraceWriter(path, log_attributes={"spec": "medication_dispenser"}) as writer:
        writer.add_case("user-0", dispenser_day, {"user": 0})
        writer.add_case("user-1", dispenser_day)
    head = read_trace_header(path)
    assert (head["format"], head["version"]) == (TRACE_FORMAT, TRACE_FORMAT_VERSION)
    assert head["cases"] is True and head["spec"] == "medication_dispenser"
    lines = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()[1:]]
    assert lines[0] == {"seq": 0, "time": 0.0, "kind": "case.started", "case": "user-0",
                        "data": {"user": 0}}
    events = lines[1:]
    assert len(events) == 2 * len(dispenser_day)
    assert [e["case"] for e in events] == (["user-0"] * len(dispenser_day)
                                           + ["user-1"] * len(dispenser_day))
    assert writer.cases == 2 and writer.events == 2 * len(dispenser_day)


def test_jsonl_export_reads_back_as_the_same_events(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    path = tmp_path / "traces.jsonl"
    with JsonlTraceWriter(path) as writer:
        writer.add_case("u", dispenser_day)
    assert list(read_trace(path)) == [TraceEvent.from_json(e.to_json()) for e in dispenser_day]


def test_jsonl_export_keeps_every_kind(tmp_path: Path,
                                       dispenser_day: list[TraceEvent]) -> None:
    path = tmp_path / "traces.jsonl"
    with JsonlTraceWriter(path) as writer:
        writer.add_case("u", dispenser_day)
    kinds = {e.kind for e in read_trace(path)}
    assert {EventKind.TRIGGER_RAISED, EventKind.DATA_CHANGED, EventKind.RUN_STARTED} <= kinds


def test_jsonl_export_appears_only_when_closed(tmp_path: Path) -> None:
    path = tmp_path / "traces.jsonl"
    writer = JsonlTraceWriter(path)
    writer.add_case("u", [TraceEvent(1.0, EventKind.ACTIVITY_STARTED)])
    assert not path.exists()
    writer.close()
    assert path.exists() and not (tmp_path / "traces.jsonl.partial").exists()
    with pytest.raises(EvaluationError, match="already closed"):
        writer.add_case("late", [])


def test_unwritable_jsonl_export_is_an_evaluation_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(EvaluationError, match=r"cannot write the trace export .*\.jsonl"):
        JsonlTraceWriter(blocker / "traces.jsonl")


# --------------------------------------------------------------------------- streaming

def synthetic_case(template: list[TraceEvent], day: int) -> Iterator[TraceEvent]:
    """A case built lazily from a template, so the test itself holds no cases."""
    for event in template:
        yield TraceEvent(event.time + 86_400.0 * day, event.kind, event.process,
                         event.instance, event.activity, event.lane, event.participant,
                         event.package, event.data, event.seq)


@pytest.mark.parametrize("writer_class", [XesWriter, JsonlTraceWriter], ids=["xes", "jsonl"])
def test_exporting_many_cases_keeps_memory_flat(
        tmp_path: Path, dispenser_day: list[TraceEvent],
        writer_class: type[XesWriter | JsonlTraceWriter]) -> None:
    """Flat means no memory per case written: what the writer holds after 1,100 cases and
    after 3,100 is the same up to 16 bytes a case (holding each case's name alone would be
    about 60), and no case costs more at its peak than the first hundred did (the file
    buffer and caches do not grow with the number of cases). Two sizes show the growth as
    well as 10,000 cases did, for a third of the traced allocations.

    The peaks are taken per hundred cases, and the three largest of the thirty are left out:
    tracemalloc counts every thread of the process (a pytest-xdist worker runs a messaging
    thread beside the test), and clean CI runs saw 350 KB more within one such window, and
    once 87 KB more within two, not reproduced alone (a buffer that grew with the cases would
    raise every window after it, not two or three)."""
    # the user's part of a dispensing dose: prompts and completions; 6 events a case
    template = [e for e in dispenser_day if e.lane == "user" or e.kind ==
                EventKind.DEADLINE_EXPIRED][:6]
    path = tmp_path / "traces.out"
    held: dict[int, int] = {}
    peaks: list[int] = []                    # per hundred cases
    tracemalloc.start()
    try:
        with writer_class(path) as writer:
            for case in range(3_100):
                writer.add_case(f"user-{case}", synthetic_case(template, case), {"user": case})
                if (case + 1) % 100 == 0:
                    now, peak = tracemalloc.get_traced_memory()
                    peaks.append(peak)
                    tracemalloc.reset_peak()
                    if case + 1 in (1_100, 3_100):
                        held[case + 1] = now
    finally:
        tracemalloc.stop()
    assert writer.cases == 3_100
    growth = held[3_100] - held[1_100]
    assert growth < 16 * 2_000, (held, growth)
    first, later = peaks[0], sorted(peaks[1:])[:-3]
    assert max(later) < 2 * first + 64 * 1024, peaks
    with path.open(encoding="utf-8") as handle:
        if writer_class is XesWriter:
            assert sum(1 for line in handle if line.strip() == "<trace>") == 3_100
        else:
            assert sum(1 for line in handle if '"case.started"' in line) == 3_100
