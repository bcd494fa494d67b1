"""`opspec evaluate --workers 2` asks for the report's figures that need neither the sample
index nor the summaries (counts over time, the user's actions) as soon as the last
replication is stored, in one batch for one drawing process, so that they are drawn while
the evaluate process builds the index and the summaries (``report.ask_figures_ahead``,
``plots.asked_ahead``). The report must be the one drawn without that: every figure asked
for once, the same bytes; a read that fails ahead leaves the figures to the report."""

from __future__ import annotations

import inspect
import multiprocessing
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from evaluation_inputs import SPEC
from figure_samples import DAYS, figures

from opspec.errors import EvaluationError
from opspec.evaluation import (
    drawing_pools,
    figure_queue,
    plots,
    report,
    report_design,
    sample_index,
)
from opspec.evaluation.store import ResultStore


def _hours(folder: Path) -> Path:
    return plots.time_of_day_figure({k: [*v, *[0] * 19] for k, v in DAYS.items()},
                                    folder / "hours.svg")


def test_figures_asked_ahead_are_sent_in_one_batch_and_drawn_as_in_turn(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = [_hours(tmp_path / "alone"), *figures(tmp_path / "alone")]
    sent: list[Any] = []
    with plots.drawing_processes(2):
        pools = drawing_pools.started_pools()
        assert pools is not None
        submit = pools.submit

        def spy(fn: Any, /, *args: Any) -> Any:
            sent.append((fn.__name__, [job[0] for job in args[0]] if fn.__name__ ==
                         "_draw_all_named" else [args[0]]))
            return submit(fn, *args)

        monkeypatch.setattr(pools, "submit", spy)
        with plots.asked_ahead(2) as ahead:
            first = [_hours(tmp_path / "together")]
            assert sent == []                   # sent as the block ends, not as asked
        # one batch, for one process: the other is left to the evaluate process's core
        assert sent == [("_draw_all_named", ["time_of_day_figure"])]
        with plots.drawn_by(2, ahead):
            together = first + figures(tmp_path / "together")
    # the figures asked ahead are not sent again; the others one at a time as asked for
    assert [names for _, names in sent[1:]] == [["rates_figure"], ["over_days_figure"],
                                                ["latency_figure"]]
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]


def test_asked_ahead_with_one_worker_draws_them_at_once(tmp_path: Path) -> None:
    with plots.asked_ahead(1) as ahead:
        path = _hours(tmp_path)
        assert path.is_file()
    assert ahead.queue == []


def _evaluate(evaluate: Any, out: Path, workers: int) -> dict[str, bytes]:
    status, _, err = evaluate(str(SPEC), "--users", "6", "--days", "2", "--seed", "3",
                              "--workers", str(workers), "--quiet", "--out", str(out))
    assert status == 0, err
    return {p.name: p.read_bytes() for p in sorted((out / "figures").iterdir())}


def test_evaluate_asks_them_as_the_index_is_built_beside_and_once(
        evaluate: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = _evaluate(evaluate, tmp_path / "one", 1)
    order: list[str] = []
    indexing, asking = ResultStore.index, report.ask_figures_ahead
    queued = plots.drawn_by

    def index(store: ResultStore, *, beside: bool = False) -> None:
        order.append("index beside" if beside else "index")
        indexing(store, beside=beside)

    def ask(*args: Any, **kwargs: Any) -> Any:
        ahead = asking(*args, **kwargs)
        order.append("ahead: " + ", ".join(sorted(job[0].__name__
                                                  for job in ahead.figures.queue)))
        return ahead

    @contextmanager
    def drawn_by(workers: int, ahead: Any = None) -> Iterator[None]:
        order.append(f"report: {len(ahead.queue) if ahead is not None else None} ahead")
        with queued(workers, ahead):
            yield
            # the report's figures, those asked ahead among them: each asked for once
            paths = [inspect.signature(draw).bind(*args, **kwargs).arguments["path"]
                     for draw, args, kwargs, _ in ahead.queue]
            order.append(f"{len(paths)} figures, {len(set(paths))} paths")

    monkeypatch.setattr(ResultStore, "index", index)
    monkeypatch.setattr(report, "ask_figures_ahead", ask)
    monkeypatch.setattr(plots, "drawn_by", drawn_by)
    together = _evaluate(evaluate, tmp_path / "two", 2)
    assert order == ["index beside",
                     "ahead: activity_rates_figure, over_days_figure, time_of_day_figure",
                     "report: 3 ahead", f"{len(alone)} figures, {len(alone)} paths"]
    assert together == alone


def test_a_read_that_fails_ahead_leaves_the_figures_to_the_report(
        evaluate: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = _evaluate(evaluate, tmp_path / "one", 1)
    reads = report_design._activity_rates
    failed: list[str] = []

    def fails_once(store: ResultStore, design: str) -> Any:
        if not failed:
            failed.append(design)
            raise EvaluationError("cannot read the stored results")
        return reads(store, design)

    monkeypatch.setattr(report_design, "_activity_rates", fails_once)
    assert _evaluate(evaluate, tmp_path / "two", 2) == alone
    assert failed == ["A"]


def test_ctrl_c_at_the_index_does_not_wait_for_the_figures_sent(
        evaluate: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The figures asked ahead are in a drawing process (slowed to 30 s here) when Ctrl-C
    comes, as the evaluate process waits for the index built beside it: the command stops
    at once with the usual message, the replications stored, no drawing process or thread
    left, nor the thread that built the index."""
    drawing, sent = figure_queue._draw_named, tmp_path / "a figure asked ahead is drawn"

    def slow(*job: Any) -> None:        # in the drawing process (forked after this patch)
        sent.touch()
        time.sleep(30)
        drawing(*job)

    def interrupted(indexing: Any) -> None:
        for _ in range(200):                # the figures sent are being drawn
            if sent.exists():
                break
            time.sleep(0.05)
        raise KeyboardInterrupt

    monkeypatch.setattr(figure_queue, "_draw_named", slow)
    monkeypatch.setattr(sample_index.IndexBeside, "wait", interrupted)
    before = len(multiprocessing.active_children())
    started = time.monotonic()
    status, _, err = evaluate(str(SPEC), "--users", "6", "--days", "2", "--seed", "3",
                              "--workers", "2", "--quiet", "--out", str(tmp_path / "run"))
    assert time.monotonic() - started < 20
    assert sent.exists()
    assert status == 130
    assert "opspec evaluate: stopped; 6 of 6 replications are stored" in err
    assert len(multiprocessing.active_children()) == before
    assert not [t for t in threading.enumerate() if t.is_alive()
                and t.name in ("opspec-drawing", "opspec-sample-index")]
    assert not (tmp_path / "run" / "figures").exists()
