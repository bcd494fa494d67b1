"""With started drawing processes (``opspec evaluate --workers W``), each of the report's
figures is sent to them as the report asks for it, so they draw while the evaluate process
still works out the rest of the report: the same bytes as drawn one after another, and a
figure that cannot be written is the same plain error."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import EvaluationError
from opspec.evaluation import figure_queue, plots

RATES = [("doses missed", 0.0034, 0.001, 0.008), ("doses taken", 0.95, 0.93, 0.97)]
HOURS = {"alarms": [h % 5 for h in range(24)]}


def test_a_figure_is_drawn_before_the_report_is_done_asking(tmp_path: Path) -> None:
    alone = [plots.rates_figure(RATES, tmp_path / "alone" / "rates.svg"),
             plots.time_of_day_figure(HOURS, tmp_path / "alone" / "hours.svg")]
    with plots.drawing_processes(2), plots.drawn_by(2):
        first = plots.rates_figure(RATES, tmp_path / "sent" / "rates.svg")
        sent = figure_queue._SENT.get()
        assert sent is not None and list(sent) == [0]
        sent[0].result()                    # drawn by a started process, block still open
        assert first.is_file()
        second = plots.time_of_day_figure(HOURS, tmp_path / "sent" / "hours.svg")
    assert [first.read_bytes(), second.read_bytes()] == [p.read_bytes() for p in alone]


def test_a_sent_figure_that_cannot_be_written_is_a_plain_error(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("a file where the figures' folder would be")
    with pytest.raises(EvaluationError, match="cannot write the figure"):
        with plots.drawing_processes(2), plots.drawn_by(2):
            plots.rates_figure(RATES, tmp_path / "taken" / "rates.svg")
            plots.time_of_day_figure(HOURS, tmp_path / "hours.svg")


def test_without_started_processes_nothing_is_sent(tmp_path: Path) -> None:
    with plots.drawn_by(2):
        path = plots.rates_figure(RATES, tmp_path / "rates.svg")
        assert figure_queue._SENT.get() is None and not path.exists()
    assert path.is_file()
