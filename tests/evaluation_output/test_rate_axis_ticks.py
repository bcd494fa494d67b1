"""A rate panel's tick labels say where the ticks are: with ticks 1.5 % apart (a 100 % taken
rate with its interval from 97.66 %, 20 users x 2 days of the dispenser) the axis read
"94 %, 96 %, 98 %, 99 %" under ticks at 94.5, 96, 97.5 and 99 %, and the interval's lower
end was drawn right of the "98 %" tick."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.evaluation import figure_files, plots


@pytest.mark.parametrize("rows", [
    [("taken rate", 1.0, 0.9766, 1.0), ("missed rate", 0.0, 0.0, 0.0234)],
    [("missed rate", 0.0029, 0.0022, 0.0039)],
    [("taken rate", 0.5, 0.31, 0.69)],
], ids=["near-100-and-0", "rare", "middle"])
def test_every_percent_tick_label_is_its_ticks_value(
        rows: list[tuple[str, float, float, float]], tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    drawn: list[Any] = []
    save = figure_files.save

    def keep(fig: Any, path: Path) -> Path:
        written = save(fig, path)
        drawn.append(fig)
        return written

    monkeypatch.setattr(figure_files, "save", keep)
    plots.rates_figure(rows, tmp_path / "rates.svg")
    (fig,) = drawn
    checked = 0
    for ax in fig.axes:
        formatter = ax.xaxis.get_major_formatter()
        low, high = ax.get_xlim()
        for tick in ax.xaxis.get_majorticklocs():
            if not low - 1e-12 <= tick <= high + 1e-12:
                continue
            label = formatter(tick)
            assert label.endswith("%"), label
            assert float(label.rstrip("% ")) == pytest.approx(tick * 100.0, abs=1e-9), (
                f"the tick at {tick * 100.0:g} % is labelled {label!r}")
            checked += 1
    assert checked >= 2 * len(rows)
