"""Every figure of the evaluation report is a real PNG, for normal data and for no data."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opspec.errors import EvaluationError
from opspec.evaluation import plots

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

RNG = np.random.default_rng(20260105)
LATENCIES = RNG.lognormal(4.0, 0.5, 400).tolist()

Draw = Callable[[Path], Path]

NORMAL: dict[str, Draw] = {
    "latency": lambda p: plots.latency_figure("report_latency_s", LATENCIES, p),
    "latency-one-value": lambda p: plots.latency_figure("walk_s", [42.0], p),
    "rates": lambda p: plots.rates_figure(
        [("doses missed", 0.0034, 0.001, 0.008), ("doses taken", 0.95, 0.93, 0.97)], p),
    "rates-not-proportions": lambda p: plots.rates_figure(
        [("alarms per dose", 1.2, 1.1, 1.3)], p),
    "over-days": lambda p: plots.over_days_figure(
        {"doses_taken": [4, 3, 4, 4, 2], "$doses_missed$_": [0, 1, 0, 0, 2]}, p),
    "time-of-day": lambda p: plots.time_of_day_figure(
        {"alarms": [0] * 8 + [30] + [0] * 3 + [30] + [0] * 5 + [30] + [0] * 3 + [30] + [0]}, p),
    "activity-rates": lambda p: plots.activity_rates_figure(
        [("hear_alarm", 0.15, 0.0), ("choose_button", 0.0, 0.05)], p),
    "comparison": lambda p: plots.comparison_figure(
        [("doses_missed", -0.01, -0.02, -0.002), ("report_latency_s", 3.2, -1.5, 7.9)], p),
}

EMPTY: dict[str, Draw] = {
    "latency": lambda p: plots.latency_figure("report_latency_s", [], p),
    "latency-only-nan": lambda p: plots.latency_figure("x", [math.nan, math.inf], p),
    "rates": lambda p: plots.rates_figure([], p),
    "over-days": lambda p: plots.over_days_figure({}, p),
    "over-days-empty-series": lambda p: plots.over_days_figure({"doses_taken": []}, p),
    "time-of-day": lambda p: plots.time_of_day_figure({}, p),
    "time-of-day-all-zero": lambda p: plots.time_of_day_figure({"alarms": [0] * 24}, p),
    "activity-rates": lambda p: plots.activity_rates_figure([], p),
    "comparison": lambda p: plots.comparison_figure([], p),
}


def assert_valid_png(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data.startswith(PNG_SIGNATURE), f"{path} is not a PNG"
    with Image.open(path) as image:
        image.verify()          # checks chunk CRCs
    with Image.open(path) as image:
        image.load()            # decodes the pixels
        size: tuple[int, int] = image.size
    assert size[0] >= 300 and size[1] >= 200, f"{path} is too small to read: {size}"
    return size


@pytest.mark.parametrize("name", list(NORMAL), ids=list(NORMAL))
def test_figure_is_a_readable_png_for_normal_data(name: str, tmp_path: Path) -> None:
    path = tmp_path / f"{name}.png"
    assert NORMAL[name](path) == path
    assert_valid_png(path)


@pytest.mark.parametrize("name", list(EMPTY), ids=list(EMPTY))
def test_figure_for_no_data_is_a_png_saying_no_observations(name: str, tmp_path: Path) -> None:
    path = tmp_path / f"{name}.png"
    assert EMPTY[name](path) == path
    assert_valid_png(path)
    # the "no observations" figure is the same picture whatever function drew it, apart
    # from its title: mostly white, so it compresses far better than any real plot
    assert path.stat().st_size < 20_000 * (plots.DPI / 110) ** 2   # 20 kB at 110 dpi


def test_figure_with_data_differs_from_its_empty_figure(tmp_path: Path) -> None:
    full = plots.latency_figure("m", LATENCIES, tmp_path / "full.png")
    empty = plots.latency_figure("m", [], tmp_path / "empty.png")
    assert full.stat().st_size > 2 * empty.stat().st_size


def test_figure_folder_is_created(tmp_path: Path) -> None:
    path = tmp_path / "plots" / "deep" / "rates.png"
    plots.rates_figure([("x", 0.5, 0.4, 0.6)], path)
    assert_valid_png(path)


def test_unwritable_figure_path_is_an_evaluation_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(EvaluationError, match=r"cannot write the figure .*rates\.png"):
        plots.rates_figure([("x", 0.5, 0.4, 0.6)], blocker / "rates.png")


def test_time_of_day_needs_24_counts_per_metric(tmp_path: Path) -> None:
    with pytest.raises(EvaluationError, match=r"'alarms' has 23 counts, expected 24"):
        plots.time_of_day_figure({"alarms": [1] * 23}, tmp_path / "t.png")


def test_hostile_labels_are_drawn_as_text(tmp_path: Path) -> None:
    # mathtext markers and markup in names must not crash the renderer
    labels = [("$\\frac{$", 0.1, 0.0, 0.2), ("$x$_$", 0.4, 0.3, 0.5),
              ("<script>", 0.2, 0.1, 0.3), ("a_b^c", 0.3, 0.2, 0.4)]
    assert_valid_png(plots.rates_figure(labels, tmp_path / "r.png"))
    assert_valid_png(plots.latency_figure("$x_", [1.0, 2.0], tmp_path / "l.png"))


def test_importing_the_output_modules_loads_no_heavy_library() -> None:
    import subprocess
    import sys

    code = ("import sys, opspec.evaluation.plots, opspec.evaluation.html, "
            "opspec.evaluation.exporters; "
            "print(sorted({'matplotlib', 'lxml', 'pm4py', 'numpy'} & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("draw", [
    lambda series, p: plots.over_days_figure(series, p),
    lambda series, p: plots.time_of_day_figure(series, p),
], ids=["over-days", "time-of-day"])
def test_an_outcome_that_never_happened_gets_no_panel_but_a_note(draw, tmp_path: Path) -> None:
    # a panel of zeros would be drawn on a made-up scale (0 to 1e-9) and read as data
    happened = [0] * 8 + [30] + [0] * 15
    alone = draw({"alarms": happened}, tmp_path / "alone.png")
    both = draw({"alarms": happened, "device_faults": [0] * 24}, tmp_path / "both.png")
    assert assert_valid_png(both) == assert_valid_png(alone)     # no second panel
    assert both.read_bytes() != alone.read_bytes()               # the note names it


def test_figures_drawn_side_by_side_are_the_figures_drawn_one_after_another(
        tmp_path: Path) -> None:
    """``opspec evaluate --workers 2`` draws its report's figures in two processes: the
    files, their names and their bytes are those drawn one after another."""
    names = ("latency", "rates", "over-days", "activity-rates")
    alone = [NORMAL[n](tmp_path / "alone" / f"{n}.svg") for n in names]
    with plots.drawn_by(2):
        together = [NORMAL[n](tmp_path / "together" / f"{n}.svg") for n in names]
        assert not any(path.exists() for path in together)      # drawn at the block's end
    assert [p.name for p in together] == [p.name for p in alone]
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]


def test_pdf_figures_side_by_side_return_the_svg_twin_the_report_shows(tmp_path: Path) -> None:
    with plots.figure_format("pdf"), plots.drawn_by(2):
        twins = [NORMAL[n](tmp_path / f"{n}.png") for n in ("rates", "comparison")]
    assert [p.name for p in twins] == ["rates.svg", "comparison.svg"]
    assert all(p.is_file() and p.with_suffix(".pdf").read_bytes().startswith(b"%PDF")
               for p in twins)


def test_a_figure_that_cannot_be_written_side_by_side_is_an_evaluation_error(
        tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with (pytest.raises(EvaluationError, match=r"cannot write the figure .*rates\.png"),
          plots.drawn_by(2)):
        plots.rates_figure([("x", 0.5, 0.4, 0.6)], tmp_path / "fine.png")
        plots.rates_figure([("x", 0.5, 0.4, 0.6)], blocker / "rates.png")
    assert (tmp_path / "fine.png").is_file()


def test_an_activity_without_a_wrong_action_has_no_error_bar_but_a_dash(tmp_path: Path
                                                                        ) -> None:
    # as in the report's table: the user model cannot do hear_alarm wrongly, so there is no
    # error rate to draw (a 0 % bar with an interval up to 2 % would read as measured)
    rows = [("hear_alarm", 0.15, None, (0.12, 0.18), (0.0, 0.02)),
            ("choose_button", 0.0, 0.05, (0.0, 0.02), (0.02, 0.09))]
    with plots.figure_format("svg"):
        svg = plots.activity_rates_figure(rows, tmp_path / "a.png").read_text(encoding="utf-8")
    patches = svg.count('id="patch_')      # the axes, 2 omission bars, 1 error bar, legend
    with plots.figure_format("svg"):
        both = plots.activity_rates_figure(
            [(*rows[0][:2], 0.0, *rows[0][3:]), rows[1]], tmp_path / "b.png"
        ).read_text(encoding="utf-8")
    assert patches == both.count('id="patch_') - 1
    assert "–" in svg and "–" not in both
