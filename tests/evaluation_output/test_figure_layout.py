"""Every kind of figure the report draws is laid out so that a reader sees every word: no
text reaches past the figure's edge, and no tick label, axis label, title, legend or note
overlaps another — with long names too (a modeller's activity names, metric names,
subgroup names), where the margins must grow.

The figures are laid out from their texts' measured sizes (opspec.evaluation.figure_layout),
not by matplotlib's constrained layout; this checks the result on the figure as drawn, with
matplotlib's own measure of every text artist placed where the drawing put it."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from opspec.evaluation import figure_files, figure_style, plots

LONG = "a_rather_long_activity_name_a_modeller_wrote_out_in_full"
LONG_METRIC = "time_from_the_alarm_to_the_caregiver_being_notified_s"


def _boxes(fig: Any) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
    """(what must not overlap, what must only stay inside the figure) as (name, window
    extent) pairs, the figure freshly drawn."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    laid: list[tuple[str, Any]] = []
    inside: list[tuple[str, Any]] = []

    def add(where: list[tuple[str, Any]], name: str, artist: Any) -> None:
        if artist is not None and artist.get_visible() and (
                not hasattr(artist, "get_text") or artist.get_text()):
            box = artist.get_window_extent(renderer)
            if box.width > 0 and box.height > 0:
                where.append((name, box))

    for i, ax in enumerate(fig.axes):
        for axis in (ax.xaxis, ax.yaxis):
            low, high = sorted(axis.get_view_interval())
            span = high - low
            locs = axis.get_majorticklocs()
            for loc, label in zip(locs, axis.get_majorticklabels(), strict=False):
                if ax.axison and low - 1e-9 * span <= loc <= high + 1e-9 * span:
                    add(laid, f"axes {i} {axis.axis_name} tick {label.get_text()!r}", label)
            if ax.axison:
                add(laid, f"axes {i} {axis.axis_name} label", axis.label)
        for loc in ("left", "center", "right"):
            if ax.get_title(loc):
                title = next(t for t in ax.get_children() if getattr(t, "get_text", None)
                             and t.get_text() == ax.get_title(loc) and t not in ax.texts)
                add(laid, f"axes {i} title {loc}", title)
        add(laid, f"axes {i} legend", ax.get_legend())
        for text in ax.texts:
            add(inside, f"axes {i} annotation {text.get_text()!r}", text)
    for text in fig.texts:          # the note under the figure (supxlabel) among them
        add(laid, f"figure text {text.get_text()!r}", text)
    return laid, inside


def layout_faults(fig: Any) -> list[str]:
    """What a reader would find wrong with ``fig``'s layout: a text (partly) outside the
    figure, two texts over each other."""
    laid, inside = _boxes(fig)
    width, height = fig.bbox.width, fig.bbox.height
    faults = []
    for name, box in laid + inside:
        if box.x0 < -0.5 or box.y0 < -0.5 or box.x1 > width + 0.5 or box.y1 > height + 0.5:
            faults.append(f"{name} reaches past the figure: {box.bounds}")
    for k, (name, box) in enumerate(laid):
        for other, second in laid[k + 1:]:
            if _overlap(box, second) > 0.5:
                faults.append(f"{name} overlaps {other}")
    return faults


def _overlap(a: Any, b: Any) -> float:
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return min(w, h) if w > 0 and h > 0 else 0.0


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[Any]]:
    """The figures drawn in the test, kept after their function wrote them."""
    figures: list[Any] = []
    save = figure_files.save

    def keep(fig: Any, path: Path) -> Path:
        written = save(fig, path)
        figures.append(fig)
        return written

    monkeypatch.setattr(figure_files, "save", keep)
    yield figures


def _rates(path: Path) -> Path:
    return plots.rates_figure([("taken rate", 0.9964, 0.996, 0.9967),
                               (f"{LONG} missed", 0.0036, 0.0033, 0.004),
                               ("alarms per dose", 1.176, 1.174, 1.179)], path)


def _per_user(path: Path) -> Path:
    import numpy as np

    rng = np.random.default_rng(4)
    return plots.per_user_figure(
        {"missed_rate": [0.0] * 640 + [1 / 120] * 290 + [2 / 120] * 70,
         LONG_METRIC: list(rng.gamma(4.0, 30.0, 1000)),
         "alarms": list(rng.poisson(140_000, 1000).astype(float))},
        path, units={"missed_rate": "%", LONG_METRIC: "s"})


def _latency(path: Path) -> Path:
    import numpy as np

    values = list(np.random.default_rng(1).lognormal(4.2, 0.8, 5000))
    return plots.latency_figure(LONG_METRIC, values, path, total=120_000)


def _over_days(path: Path) -> Path:
    return plots.over_days_figure(
        {"doses_missed": [0.013, 0.017, 0.02, 0.009] * 7 + [0.01, 0.012],
         f"{LONG}_count": [4.0] * 30, "alarms": [4.7] * 30, "device_faults": [0.0] * 30},
        path, bands={"doses_missed": [(0.005, 0.03)] * 30})


def _hours(path: Path) -> Path:
    hours = [0] * 24
    hours[8], hours[12], hours[18] = 3_000_000, 2_900_000, 3_100_000
    return plots.time_of_day_figure({"doses_due": hours, LONG: [h // 1000 for h in hours],
                                     "device_faults": [0] * 24}, path)


def _activities(path: Path) -> Path:
    return plots.activity_rates_figure(
        [("hear_alarm", 0.1529, 0.0, (0.148, 0.158), (0.0, 0.001)),
         (LONG, 0.0, 0.0479, (0.0, 0.001), (0.045, 0.051)),
         ("take_pill", 1.0, 0.0, (0.99, 1.0), (0.0, 0.01)),
         ("choose_button", 0.0, float("nan"))], path)


def _comparison(path: Path) -> Path:
    # with a difference the paired method gives no interval (named in a note) and a
    # non-finite one (counted in the other): both notes in the figure, apart
    return plots.comparison_figure([("missed_rate", -0.002, -0.003, -0.001),
                                    (LONG_METRIC, 12.5, -3.0, 28.0),
                                    ("alarms", 0.0, 0.0, 0.0),
                                    ("report_latency_s", 0.0, None, None),
                                    ("device_faults", float("nan"), 0.0, 0.0)], path,
                                   units={"missed_rate": "pp", LONG_METRIC: "s"},
                                   no_interval={"report_latency_s": "fewer than 2 users' "
                                                "durations differ between the designs"})


def _subgroups(path: Path) -> Path:
    return plots.subgroups_figure("missed_rate", {
        "all users": [0.0, 0.01, 0.02, 0.0, 0.0, 0.03] * 50,
        f"{LONG} (mild impairment)": [0.0, 0.02, 0.05] * 40}, path, unit="%")


def _parameters(path: Path) -> Path:
    return plots.parameters_figure({
        "response_time_scale_s": {"all": [20.0, 30.0, 45.0, 25.0] * 30,
                                  f"{LONG} group": [60.0, 80.0, 75.0] * 20},
        "omission_probability": {"all": [0.01, 0.02, 0.05] * 40}}, path)


def _sweep(path: Path) -> Path:
    return plots.sweep_figure(
        "reminder_delay_s", [60.0, 120.0, 300.0, 600.0], ["1 min", "2 min", "5 min", "10 min"],
        {"missed_rate": ([0.002, 0.003, 0.006, 0.011], [0.001, 0.002, 0.004, 0.008],
                         [0.003, 0.004, 0.008, 0.014]),
         LONG_METRIC: ([100.0, 130.0, 250.0, 480.0], [90.0, 120.0, 230.0, 450.0],
                       [110.0, 140.0, 270.0, 510.0])},
        path, percent={"missed_rate": True}, units={LONG_METRIC: "s"},
        targets={"missed_rate": [("missed_rate < 0.5 %", 0.005)]},
        per_user={"missed_rate": ("95th percentile over users", [0.01, 0.012, 0.02, 0.03])})


def _empty(path: Path) -> Path:
    return plots.latency_figure(LONG_METRIC, [], path)


def _alike(*names: str) -> dict[str, Any]:
    """The marks of intervals of no width from 3 users all alike (docs/evaluation.md,
    Intervals of no width): the panels marked, and the note under the figure."""
    from opspec.evaluation.no_spread_notes import no_spread_note
    from opspec.statistics.no_spread import no_spread

    return {"no_spread": list(names),
            "no_spread_note": no_spread_note([{"ci95_no_spread": no_spread([4, 4], 3)}])}


def _over_days_alike(path: Path) -> Path:
    # with the note on what never happened above it
    return plots.over_days_figure(
        {f"{LONG}_count": [4.0] * 30, "alarms": [4.7] * 30, "device_faults": [0.0] * 30},
        path, bands={f"{LONG}_count": [(4.0, 4.0)] * 30}, **_alike(f"{LONG}_count"))


def _comparison_alike(path: Path) -> Path:
    # with the note on a difference without an interval above it
    return plots.comparison_figure([("alarms", 4.0, 4.0, 4.0),
                                    ("report_latency_s", 0.0, None, None)], path,
                                   no_interval={"report_latency_s": "fewer than 2 users' "
                                                "durations differ between the designs"},
                                   **_alike("alarms"))


def _sweep_alike(path: Path) -> Path:
    return plots.sweep_figure(
        "reminder_delay_s", [60.0, 120.0], ["1 min", "2 min"],
        {"alarms": ([4.0, 4.0], [4.0, 4.0], [4.0, 4.0]),
         LONG_METRIC: ([100.0, 130.0], [90.0, 120.0], [110.0, 140.0])}, path,
        **_alike("alarms"))


FIGURES: dict[str, Callable[[Path], Path]] = {
    "rates": _rates, "per-user": _per_user, "latency": _latency, "over-days": _over_days,
    "hours": _hours, "activities": _activities, "comparison": _comparison,
    "subgroups": _subgroups, "parameters": _parameters, "sweep": _sweep, "empty": _empty,
    "over-days-alike": _over_days_alike, "comparison-alike": _comparison_alike,
    "sweep-alike": _sweep_alike}


@pytest.mark.parametrize("kind", sorted(FIGURES))
def test_no_text_is_clipped_or_overlaps_another(kind: str, drawn: list[Any],
                                                tmp_path: Path) -> None:
    with plots.figure_format("svg"):
        FIGURES[kind](tmp_path / f"{kind}.svg")
    assert len(drawn) == 1
    assert layout_faults(drawn[0]) == []


def test_long_names_widen_the_margin_instead_of_leaving_the_figure(
        drawn: list[Any], tmp_path: Path) -> None:
    """The activity names are the y axis' tick labels: a long one moves the plot right,
    the short ones' plot starts further left."""
    plots.activity_rates_figure([("take_pill", 0.1, 0.0)], tmp_path / "short.png")
    plots.activity_rates_figure([(LONG, 0.1, 0.0)], tmp_path / "long.png")
    short, long_ = (fig.axes[0].get_position().x0 for fig in drawn)
    assert long_ > short + 0.2
    assert all(layout_faults(fig) == [] for fig in drawn)


def test_the_check_finds_a_clipped_label_and_an_overlap(drawn: list[Any],
                                                        tmp_path: Path) -> None:
    """The checker itself: a figure with its margins taken away, and one with its panels
    pushed against each other, is found wrong."""
    _over_days(tmp_path / "days.png")
    _per_user(tmp_path / "per-user.png")
    days, per_user = drawn
    days.subplots_adjust(left=0.0)
    assert any("reaches past the figure" in f for f in layout_faults(days))
    per_user.subplots_adjust(hspace=0.0)      # a panel's tick labels on the next one's
    assert any("overlaps" in f for f in layout_faults(per_user))


def test_panels_share_the_figure_evenly() -> None:
    """Stacked panels get the same height and the plot fills the figure but for the
    margins the texts need (no panel squeezed, no large empty band)."""
    import matplotlib

    from opspec.evaluation.figure_layout import lay_out

    with figure_style._figure(9.0, 6.0) as fig:
        axes = figure_style._panels(fig, 3)
        for ax in axes:
            ax.set_ylabel("count")
        axes[-1].set_xlabel("simulated day")
        assert lay_out(fig)
        heights = [ax.get_position().height for ax in axes]
        assert max(heights) - min(heights) < 1e-9
        top = axes[0].get_position().y1
        bottom = axes[-1].get_position().y0
        # the margins are a few lines of text at 11 pt, not a tenth of a 6-inch figure
        line = 11 / 72 / 6.0
        assert 1.0 - top < 2 * line and bottom < 6 * line
        assert math.isclose(matplotlib.rcParams["font.size"], 11)


def test_a_figure_off_the_grid_is_left_to_the_constrained_layout() -> None:
    """An axes placed by hand (not a cell of the figure's grid) is not something the
    measured layout knows: it says so, and the figure is laid out by matplotlib's
    constrained layout instead, its texts inside the figure all the same."""
    from opspec.evaluation.figure_layout import lay_out

    with figure_style._figure(6.0, 4.0) as fig:
        ax = fig.add_subplot()
        ax.set_yticks([0.0, 1.0], ["none", LONG])
        ax.set_xlabel("simulated day")
        inset = fig.add_axes((0.6, 0.6, 0.3, 0.3))
        inset.set_title("inset")
        assert not lay_out(fig)
        figure_files._lay_out(fig)
        laid, _ = _boxes(fig)
        width, height = fig.bbox.width, fig.bbox.height
        assert all(box.x0 >= -0.5 and box.x1 <= width + 0.5 and box.y0 >= -0.5
                   and box.y1 <= height + 0.5 for name, box in laid
                   if name.startswith("axes 0"))
