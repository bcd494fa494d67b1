"""JSON Lines sink round trip, trace header, metric shapes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from builders import act, count, duration, pkg, proc, ratio
from engine_runs import run

from opspec.engine.metrics import MetricsListener, percentile
from opspec.engine.simulation import Simulation
from opspec.engine.trace import TraceEvent
from opspec.engine.trace_sinks import JsonlSink, read_trace, read_trace_header
from opspec.errors import ExecutionError


def _model() -> object:
    return pkg(proc("p", ["a", act("b", cpu=2.5, assign=[("x", "'done'")])], [("a", "b")],
                    start="period:10"),
               metrics=[count("runs", "process.started", "p"),
                        count("bs", "activity.completed", "p", "b"),
                        duration("a_to_b", ("activity.started", "p", "a"),
                                 ("activity.completed", "p", "b")),
                        ratio("b_per_run", "bs", "runs")])


def test_jsonl_sink_round_trips_every_event(tmp_path: Path) -> None:
    path = tmp_path / "trace.jsonl"
    with JsonlSink(path, header={"seed": 3}) as sink:
        sim = Simulation(_model(), listeners=[sink], keep_trace=True, seed=3)
        result = sim.run(until=25.0)
    header = read_trace_header(path)
    assert header["format"] == "opspec-trace" and header["version"] == 1 and header["seed"] == 3
    loaded = list(read_trace(path))
    assert loaded == list(result.trace or ())


def test_truncated_last_line_is_skipped_and_a_foreign_file_rejected(tmp_path: Path) -> None:
    path = tmp_path / "trace.jsonl"
    with JsonlSink(path) as sink:
        sink(TraceEvent(1.0, "fault", seq=1))
    with open(path, "a", encoding="utf-8") as handle:
        handle.write('{"seq": 2, "time": 2.0, "ki')
    assert [e.seq for e in read_trace(path)] == [1]
    other = tmp_path / "other.jsonl"
    other.write_text(json.dumps({"hello": 1}) + "\n")
    with pytest.raises(ExecutionError, match="not an opspec trace"):
        list(read_trace(other))


def test_metrics_have_the_shared_output_shape() -> None:
    result = run(_model(), until=25.0)
    metrics = result.metrics
    assert metrics["runs"] == {"kind": "count", "total": 3}
    assert metrics["bs"] == {"kind": "count", "total": 3}
    assert metrics["a_to_b"] == {"kind": "duration", "n": 3, "mean": 2.5, "p95": 2.5,
                                 "min": 2.5, "max": 2.5}
    assert metrics["b_per_run"] == {"kind": "ratio", "value": 1.0}


def test_metrics_listener_computes_the_same_from_a_stored_trace(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    model = _model()
    with JsonlSink(path) as sink:
        live = Simulation(model, listeners=[sink]).run(until=25.0).metrics
    replay = MetricsListener(model.metrics)  # type: ignore[attr-defined]
    for event in read_trace(path):
        replay(event)
    assert replay.values() == live


def test_percentile_interpolates_like_numpy() -> None:
    import numpy as np

    values = [3.0, 1.0, 4.0, 1.5, 9.0, 2.6]
    assert percentile(values, 95) == pytest.approx(float(np.percentile(values, 95)))


def test_events_nobody_wants_are_not_built() -> None:
    got: list[TraceEvent] = []

    class OnlyB:
        selects = frozenset({("activity.completed", "p", "b")})

        def __call__(self, event: TraceEvent) -> None:
            got.append(event)

    Simulation(_model(), listeners=[OnlyB()]).run(until=25.0)
    assert {(e.kind, e.activity) for e in got} == {("activity.completed", "b")}
