"""A run's own metrics, when they are its one raw listener, are taken by ``RunState.emit`` in
line (``MetricsListener.raw``'s steps, without its call): the counts, the duration samples and
their kept times are those ``raw`` computes, which the run uses whenever another raw
listener hears the events too."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.metrics import MetricsListener
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]


def _run(beside: bool, keep_times: bool) -> tuple[Any, ...]:
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    user = model.performer(user_stream(11, 0))
    other = MetricsListener(compiled.package.metrics)
    other.keep_times = keep_times
    sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                     seed=11, scope=(0,), listeners=[other] if beside else [])
    assert sim.metrics is not None
    sim.metrics.keep_times = keep_times
    assert (sim.one_metric is sim.metrics) is not beside
    result = sim.run(until=8 * 86400.0)
    mine = sim.metrics
    if beside:      # the other listener heard the same events through raw
        assert other.values() == mine.values()
        assert (other.samples, other.count_times, other.sample_times) == (
            mine.samples, mine.count_times, mine.sample_times)
    return (result.metrics, mine.counts, mine.samples, mine.count_times, mine.sample_times,
            result.summary)


@pytest.mark.parametrize("keep_times", [False, True], ids=["plain", "times kept"])
def test_the_metrics_taken_in_line_are_those_raw_takes(keep_times: bool) -> None:
    in_line = _run(beside=False, keep_times=keep_times)
    through_raw = _run(beside=True, keep_times=keep_times)
    assert in_line == through_raw
    _, counts, samples, count_times, sample_times, _ = in_line
    assert counts["doses_due"] == 32 and counts["doses_taken"] > 20
    assert len(samples["report_latency_s"]) == counts["doses_taken"]
    if keep_times:
        assert len(count_times["doses_due"]) == 32
        assert len(sample_times["report_latency_s"]) == counts["doses_taken"]
    else:
        assert not count_times and not sample_times


def test_every_role_in_line_as_raw_takes_it() -> None:
    """Counts, a duration from the first start and one from the last start, the start and
    end on one event, events of two instances interleaved: emit's steps against raw's."""
    from builders import manual, pkg, proc
    from test_metrics_matching import COMPLETED, STARTED, _listener

    sim = Simulation(compile_package(pkg(proc("p", [manual("a")], []))))
    for keep_times in (False, True):
        in_line, by_raw = _listener(), _listener()
        in_line.keep_times = by_raw.keep_times = keep_times
        sim.one_metric = in_line
        events = [(STARTED, "notify", "alarm", 1), (STARTED, "notify", "alarm", 2),
                  (COMPLETED, "notify", "alarm", 1), (STARTED, "notify", "alarm", 1),
                  (COMPLETED, "notify", "report", 2), (COMPLETED, "notify", "report", 1),
                  (COMPLETED, "other", "x", None), (STARTED, "notify", "alarm", None),
                  (COMPLETED, "notify", "report", None)]
        for n, (kind, process, activity, instance) in enumerate(events):
            sim.now = float(n)
            sim.emit(kind, process, instance, activity)
            by_raw.raw(float(n), kind, process, instance, activity)
        assert in_line.values() == by_raw.values()
        assert (in_line.counts, in_line.samples, in_line.count_times, in_line.sample_times
                ) == (by_raw.counts, by_raw.samples, by_raw.count_times, by_raw.sample_times)
        assert in_line.samples["latency"] and in_line.counts["any_done"] == 5
