"""``opspec evaluate --workers W`` starts the report's drawing processes
(``plots.drawing_processes``) before it knows what to draw: the figures they draw must
be those drawn one after another, and what could not be sent to them is still drawn."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import EvaluationError
from opspec.evaluation import figure_queue, plots

from figure_samples import RATES
from figure_samples import figures as _figures


def test_started_processes_draw_the_figures_drawn_one_after_another(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = _figures(tmp_path / "alone")
    with plots.drawing_processes(2):
        # what this process (or processes forked from it now) would draw with: it must not
        # be needed, the started processes draw every figure
        def not_here(job: object) -> None:
            raise AssertionError("drawn outside the started processes")

        monkeypatch.setattr(figure_queue, "_draw_one", not_here)
        with plots.drawn_by(2):
            together = _figures(tmp_path / "together")
            # sent to the started processes as asked for, drawn by the block's end
        assert all(p.is_file() for p in together)           # drawn before the block ends
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]


def test_a_figure_function_made_after_the_processes_started_is_still_drawn(
        tmp_path: Path) -> None:
    """A figure function the started processes do not know (made after they were forked: a
    user's own figure) is drawn all the same, and so are the others."""
    with plots.drawing_processes(2):

        @figure_queue.queueable
        def dots_figure(values: list[float], path: Path) -> Path:
            return plots.rates_figure([("dots", *values)], path)

        with plots.drawn_by(2):
            mine = dots_figure([0.5, 0.4, 0.6], tmp_path / "dots.svg")
            paths = _figures(tmp_path)
    assert mine.is_file() and all(p.is_file() for p in paths)
    assert mine.read_bytes() == plots.rates_figure([("dots", 0.5, 0.4, 0.6)],
                                                   tmp_path / "again.svg").read_bytes()


def test_a_figure_that_cannot_be_written_is_still_a_plain_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with (plots.drawing_processes(2),
          pytest.raises(EvaluationError, match=r"cannot write the figure .*rates\.svg"),
          plots.drawn_by(2)):
        plots.rates_figure(RATES, tmp_path / "fine.svg")
        plots.rates_figure(RATES, blocker / "rates.svg")
    assert (tmp_path / "fine.svg").is_file()
