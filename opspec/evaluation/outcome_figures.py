"""The figures of one design's outcomes, as the report's estimates show them: each rate with
its interval (:func:`rates_figure`), each duration's distribution (:func:`latency_figure`),
counts day by day and by hour (:func:`over_days_figure`, :func:`time_of_day_figure`), and
the user's omission and error rates per activity (:func:`activity_rates_figure`).

Each function draws one figure, writes it to ``path`` (:func:`.figure_files.save`) and
returns the path written; empty input gives a figure that says "no observations".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError
from opspec.evaluation import figure_files
from opspec.evaluation.figure_queue import queueable
from opspec.evaluation.figure_style import (
    _LINESTYLES,
    _MARKERS,
    PALETTE,
    PERCENT,
    _bar_height,
    _empty,
    _figure,
    _fmt,
    _is_rate,
    _never,
    _note,
    _note_dropped,
    _notes,
    _panels,
    _percent_axis,
    _text,
    _wrapped,
)
from opspec.evaluation.no_spread_notes import MARK

__all__ = ["activity_rates_figure", "latency_figure", "over_days_figure", "rates_figure",
           "time_of_day_figure"]


@queueable
def latency_figure(metric: str, values: Sequence[float], path: Path, *,
                   marks: Mapping[str, float | None] | None = None,
                   total: int | None = None, label: str | None = None,
                   unit: str = "s") -> Path:
    """ECDF (left) and histogram (right) of one duration metric, in seconds.

    Mean, median and 95th percentile are marked on both panels with distinct line styles and
    their values in the legend. ``marks`` gives them (``mean``, ``median``, ``p95``) computed
    from every observation when ``values`` is a sample of them; ``total`` is then the number
    of all observations, and the figure says that it draws a sample. ``label`` is the
    metric in words for the axes (default: its name), ``unit`` its unit.
    """
    import numpy as np

    metric = _text(label or metric)
    title = f"{metric}: distribution of durations"
    # the finite values as _finite keeps them, in one numpy pass (a latency sample is tens
    # of thousands of values; None becomes NaN and is left out with the others)
    every = np.asarray(values, dtype=float)
    arr = every[np.isfinite(every)]
    dropped = int(every.size - arr.size)
    del every
    if not arr.size:
        return _empty(path, title)
    given = {k: float(v) for k, v in (marks or {}).items() if v is not None}
    own = {"mean": float(arr.mean()), "median": float(np.median(arr)),
           "p95": float(np.percentile(arr, 95))}
    styles = {"mean": ("-", PALETTE[1]), "median": ("--", PALETTE[2]), "p95": (":", PALETTE[4])}
    drawn = [(name, given.get(name, own[name]), *style) for name, style in styles.items()]
    sampled = total is not None and total > arr.size
    with _figure(11.0, 4.4) as fig:
        count = (f"a sample of {arr.size:,} of {total:,} observations" if sampled
                 else f"{arr.size:,} observations")
        _note(fig, count if sampled else "")
        left, right = fig.subplots(1, 2)
        # ECDF: a step function by hand (Axes.ecdf needs matplotlib >= 3.8), at most 2,000
        # steps (quantiles 1/2000 apart): finer than a printed figure shows, and a vector
        # figure stays small
        xs = np.sort(arr)
        ys = np.arange(1, xs.size + 1) / xs.size
        if xs.size > 2000:
            keep = np.unique(np.linspace(0, xs.size - 1, 2000).round().astype(int))
            xs, ys = xs[keep], ys[keep]
        left.step(np.concatenate(([xs[0]], xs)), np.concatenate(([0.0], ys)), where="post",
                  color=PALETTE[0], linewidth=2, label="share done within x")
        left.set_title("Cumulative share of observations")
        left.set_xlabel(f"{metric} ({unit})")
        left.set_ylabel("share of observations (%)")
        left.set_ylim(0.0, 1.02)
        _percent_axis(left, "y")
        bins: Any = "auto" if np.ptp(arr) > 0 else 1
        right.hist(arr, bins=bins, histtype="stepfilled", color=PALETTE[5], edgecolor=PALETTE[0],
                   linewidth=0.8)
        right.set_title("Histogram")
        right.set_xlabel(f"{metric} ({unit})")
        right.set_ylabel("number of observations" + (" (in the sample)" if sampled else ""))
        for name, value, style, colour in drawn:
            for ax in (left, right):
                ax.axvline(value, linestyle=style, color=colour, linewidth=1.8,
                           label=f"{name} = {value:.4g} {unit}" if ax is right else None)
        right.legend(loc="best", frameon=True,
                     title="of all observations" if sampled else None)
        _note_dropped(fig, dropped)
        return figure_files.save(fig, path)


@queueable
def rates_figure(rows: Sequence[tuple[str, float, float, float]], path: Path) -> Path:
    """Each ``(label, estimate, ci_low, ci_high)`` as a point with its 95 % CI as error bars,
    each in its own panel with its own scale: a rare outcome (0.4 %) is not flattened next to
    a common one (99.6 %). Panels whose numbers all lie in [0, 1] show percentages.
    """
    from matplotlib.ticker import MaxNLocator

    title = "Outcome rates with 95 % confidence intervals"
    clean = [(_text(label), float(est), float(lo), float(hi)) for label, est, lo, hi in rows
             if all(math.isfinite(float(v)) for v in (est, lo, hi))]
    dropped = len(rows) - len(clean)
    if not clean:
        return _empty(path, title)
    with _figure(9.0, 1.3 + 0.95 * len(clean)) as fig:
        for ax, (label, est, lo, hi) in zip(_panels(fig, len(clean), sharex=False), clean,
                                            strict=True):
            percent = _is_rate([est, lo, hi])
            ax.errorbar([est], [0.0], xerr=[[max(est - lo, 0.0)], [max(hi - est, 0.0)]],
                        fmt="o", color=PALETTE[0], ecolor=PALETTE[0], capsize=5,
                        markersize=7, linewidth=1.8, clip_on=False)
            ax.set_yticks([0.0], [label])
            ax.set_ylim(-1.0, 1.0)
            ax.grid(axis="y", visible=False)
            width = hi - lo if hi > lo else max(abs(est) * 0.1, 1e-6)
            left, right = lo - 0.6 * width, hi + 1.9 * width   # room for the label
            # a rate's axis stays within [0, 100] %: near 100 % the label goes to the left
            on_left = percent and right > 1.0
            if on_left:
                left, right = lo - 1.9 * width, hi + 0.6 * width
            text = f"{_fmt(est, percent)}  [{_fmt(lo, percent)}, {_fmt(hi, percent)}]"
            ax.annotate(text, (lo, 0.0) if on_left else (hi, 0.0),
                        xytext=(-6 if on_left else 6, 0), textcoords="offset points",
                        va="center", ha="right" if on_left else "left", fontsize=9)
            locator = MaxNLocator(6)
            if percent:
                from matplotlib.ticker import PercentFormatter

                left, right = max(left, 0.0), min(right, 1.0)
                # as many decimals as the ticks the locator puts there need: a step of
                # 1.5 % printed without one labelled 94.5 % "94 %" and 97.5 % "98 %"
                ax.xaxis.set_major_formatter(PercentFormatter(
                    xmax=1.0, decimals=_tick_decimals(locator.tick_values(left, right)),
                    symbol=PERCENT))
            ax.set_xlim(left, right)
            ax.xaxis.set_major_locator(locator)
        if all(_is_rate([e, lo, hi]) for _, e, lo, hi in clean):
            fig.supxlabel("rate (% of opportunities)", fontsize=11)
        _note_dropped(fig, dropped)
        return figure_files.save(fig, path)


def _tick_decimals(ticks: Sequence[float]) -> int:
    """The decimals that print every one of ``ticks`` (fractions, shown as %) exactly."""
    for decimals in range(7):
        if all(abs(t * 100.0 * 10 ** decimals - round(t * 100.0 * 10 ** decimals)) < 1e-6
               for t in ticks):
            return decimals
    return 6


@queueable
def over_days_figure(series: Mapping[str, Sequence[float]], path: Path, *,
                     bands: Mapping[str, Sequence[tuple[float | None, float | None]]]
                     | None = None, no_spread: Sequence[str] = (),
                     no_spread_note: str | None = None) -> Path:
    """One panel per metric, each on its own scale: its value on day 1, 2, …, D, with the
    95 % interval of each day as a band when ``bands`` gives them (per metric, per day).
    The metrics in ``no_spread`` have a band of no width on some day because the few users
    were all alike: their panels are marked (†) and ``no_spread_note`` says under the
    figure what that means (:mod:`.no_spread_notes`)."""
    bands = {_text(name): list(b) for name, b in (bands or {}).items()}
    alike = {_text(name) for name in no_spread}
    title = "Outcomes over the simulated days"
    present = {_text(name): list(vals) for name, vals in series.items() if len(vals) > 0}
    never = [name for name, vals in present.items() if all(v == 0 for v in vals)]
    present = {name: vals for name, vals in present.items() if name not in never}
    if not present:
        return _empty(path, title + (": every outcome was 0 on every day" if never else ""))
    longest = max(len(v) for v in present.values())
    with _figure(9.0, 0.9 + 1.45 * len(present)) as fig:
        _note(fig, _notes(_never(never), _wrapped(no_spread_note if alike & set(present)
                                                  else None, 9.0)))
        axes = _panels(fig, len(present))
        for i, (ax, (name, vals)) in enumerate(zip(axes, present.items(), strict=True)):
            days = list(range(1, len(vals) + 1))
            ys = [float(v) if v is not None and math.isfinite(float(v)) else math.nan
                  for v in vals]
            ax.plot(days, ys, color=PALETTE[i % len(PALETTE)],
                    marker=_MARKERS[i % len(_MARKERS)] if longest <= 60 else None,
                    markersize=4, linestyle=_LINESTYLES[i % len(_LINESTYLES)], linewidth=1.6)
            band = bands.get(name)
            if band and len(band) == len(vals):
                lows = [math.nan if lo is None else float(lo) for lo, _ in band]
                highs = [math.nan if hi is None else float(hi) for _, hi in band]
                ax.fill_between(days, lows, highs, color=PALETTE[i % len(PALETTE)],
                                alpha=0.2, linewidth=0, step=None)
                ys_all = ys + [h for h in highs if math.isfinite(h)]
            else:
                ys_all = ys
            mark = f" {MARK}" if name in alike else ""
            ax.set_ylabel(f"{name}{mark}\n(per user)", rotation=0, ha="right", va="center")
            finite = [y for y in ys_all if math.isfinite(y)]
            if finite and min(finite) >= 0:
                ax.set_ylim(bottom=0, top=max(max(finite) * 1.15, 1e-9))
        axes[-1].set_xlabel("simulated day")
        axes[-1].set_xlim(0.5, longest + 0.5)
        if longest <= 10:
            axes[-1].set_xticks(range(1, longest + 1))
        elif longest <= 31:     # day 1 and every fifth: a grid a reader counts along
            axes[-1].set_xticks([1, *range(5, longest + 1, 5)])
        return figure_files.save(fig, path)


@queueable
def time_of_day_figure(series: Mapping[str, Sequence[int]], path: Path) -> Path:
    """One panel per metric, each on its own scale: how many times it happened in each hour
    of the day (0 to 23)."""
    title = "Outcomes by time of day"
    for name, counts in series.items():
        if len(counts) != 24:
            raise EvaluationError(f"time_of_day_figure: metric {name!r} has {len(counts)} "
                                  "counts, expected 24 (one per hour 0..23)")
    present = {_text(name): list(c) for name, c in series.items() if any(c)}
    never = [_text(name) for name, c in series.items() if not any(c)]
    if not present:
        return _empty(path, title + (": no outcome ever happened" if never else ""))
    with _figure(9.0, 0.9 + 1.45 * len(present)) as fig:
        _note(fig, _never(never))
        axes = _panels(fig, len(present))
        for i, (ax, (name, counts)) in enumerate(zip(axes, present.items(), strict=True)):
            # each hour is the bin [h, h+1): one outlined step patch, not 24 bar artists
            ax.stairs(counts, range(25), fill=True, facecolor=PALETTE[i % len(PALETTE)],
                      edgecolor="black", linewidth=0.6)
            # the quantity in words: events of all users and days (the day-by-day panels
            # say "per user"; these are totals)
            ax.set_ylabel(f"{name}\n(events, all users)", rotation=0, ha="right", va="center")
            ax.set_ylim(0, max(counts) * 1.15)
        axes[-1].set_xlabel("hour of the simulated day (each bar from h:00 to h:59)")
        axes[-1].set_xticks(range(0, 25, 3))
        axes[-1].set_xlim(0, 24)
        return figure_files.save(fig, path)


@queueable
def activity_rates_figure(rows: Sequence[tuple[Any, ...]], path: Path) -> Path:
    """Grouped horizontal bars: omission rate and error rate of each (manual) activity,
    ``(activity, omission, error)`` or, with their 95 % intervals drawn as error bars,
    ``(activity, omission, error, (low, high), (low, high))``. An error of ``None``: the
    user model has no wrong action for that activity; no bar is drawn, "–" is written
    (as the report's table does)."""
    title = "Omission and error rates per activity"

    def finite(value: Any) -> bool:
        return value is not None and math.isfinite(float(value))

    kept = [r for r in rows if finite(r[1]) and (r[2] is None or finite(r[2]))]
    clean = [(_text(r[0]), float(r[1]), None if r[2] is None else float(r[2])) for r in kept]
    intervals = [(r[3], r[4]) for r in kept if len(r) == 5]
    dropped = len(rows) - len(clean)
    if not clean:
        return _empty(path, title)
    percent = _is_rate([v for _, o, e in clean for v in (o, e) if v is not None])
    with _figure(8.5, _bar_height(int(1.5 * len(clean)) + 1)) as fig:
        ax = fig.add_subplot()
        n = len(clean)
        centres = list(range(n))[::-1]
        height = 0.38
        omission = ax.barh([c + height / 2 for c in centres], [o for _, o, _ in clean],
                           height=height, color=PALETTE[1], edgecolor="black", linewidth=0.5,
                           label="omission rate (not done)")
        wrong = [i for i in range(n) if clean[i][2] is not None]   # rows with an error rate
        error = ax.barh([centres[i] - height / 2 for i in wrong],
                        [clean[i][2] or 0.0 for i in wrong],
                        height=height, color=PALETTE[0], edgecolor="black", linewidth=0.5,
                        hatch="//", label="error rate (done wrongly)")
        tops = [max(o, e or 0.0) for _, o, e in clean]
        ends = [[b.get_width() for b in omission], [b.get_width() for b in error]]
        if len(intervals) == n:
            for offset, k, which in ((height / 2, 0, range(n)), (-height / 2, 1, wrong)):
                ests = [float(clean[i][1 + k] or 0.0) for i in which]
                lows = [max(0.0, ests[j] - (intervals[i][k][0] or 0.0))
                        for j, i in enumerate(which)]
                highs = [max(0.0, (intervals[i][k][1] or 0.0) - ests[j])
                         for j, i in enumerate(which)]
                ax.errorbar(ests, [centres[i] + offset for i in which], xerr=[lows, highs],
                            fmt="none", ecolor="black", capsize=3, linewidth=1.0)
            tops = [max(o, e or 0.0, intervals[i][0][1] or 0.0,
                        (intervals[i][1][1] or 0.0) if e is not None else 0.0)
                    for i, (_, o, e) in enumerate(clean)]
            ends = [[max(clean[i][1], intervals[i][0][1] or 0.0) for i in range(n)],
                    [max(clean[i][2] or 0.0, intervals[i][1][1] or 0.0) for i in wrong]]
        # each value just past its bar, or past its interval when it has one
        for bars, at in zip((omission, error), ends, strict=True):
            for bar, x in zip(bars, at, strict=True):
                ax.annotate(_fmt(bar.get_width(), percent),
                            (x, bar.get_y() + bar.get_height() / 2), xytext=(4, 0),
                            textcoords="offset points", va="center", fontsize=9)
        for i in range(n):              # no wrong action in the model: no rate to draw
            if clean[i][2] is None:
                ax.annotate("–", (0.0, centres[i] - height / 2), xytext=(4, 0),
                            textcoords="offset points", va="center", fontsize=9)
        ax.set_yticks(centres, [a for a, *_ in clean])
        # a rule between activities, none through them: a grid line at each name ran
        # between its two bars, and a 0 % label seemed to belong to the next activity
        ax.grid(axis="y", visible=False)
        for c in centres[:-1]:
            ax.axhline(c - 0.5, color="#999999", linewidth=0.6)
        ax.set_ylim(-0.5, n - 0.5)
        if percent:
            _percent_axis(ax, "x")
            ax.set_xlabel("rate (% of the times it was asked for)")
            top = max(tops)
            ax.set_xlim(0.0, min(1.0, top * 1.3 + 0.01) if top > 0 else 0.05)
        else:
            ax.set_xlabel("rate")
            ax.margins(x=0.2)
        ax.legend(loc="lower right")
        _note_dropped(fig, dropped)
        return figure_files.save(fig, path)

