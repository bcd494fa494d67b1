"""The figures of who the simulated users are and how they differ: each user's own value of
a metric over users (:func:`per_user_figure`, from a few numbers per metric:
:func:`user_distribution`), the same by subgroup (:func:`subgroups_figure`), and the
parameters drawn for the users of a population (:func:`parameters_figure`).

Each function draws one figure, writes it to ``path`` (:func:`.figure_files.save`) and
returns the path written; empty input gives a figure that says "no observations".
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from opspec.evaluation import figure_files
from opspec.evaluation.figure_queue import queueable
from opspec.evaluation.figure_style import (
    _LINESTYLES,
    PALETTE,
    _empty,
    _figure,
    _finite,
    _fmt,
    _outside_legend,
    _panels,
    _text,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes


__all__ = ["UserDistribution", "parameters_figure", "per_user_figure", "subgroups_figure",
           "user_distribution"]


@dataclass(frozen=True)
class UserDistribution:
    """What the per-user figure draws of one metric (:func:`user_distribution`), a few
    numbers whatever the number of users: the users' values (finite, scaled) ``kind``
    ``"bars"``, each distinct value (``xs``) with its number of users (``counts``), or
    ``"hist"``, numpy's ``"auto"`` bins (``xs`` their edges) with the users in each; their
    ``low`` and ``high``, ``mean`` and ``users``."""

    kind: str
    xs: tuple[float, ...]
    counts: tuple[int, ...]
    low: float
    high: float
    mean: float
    users: int


def user_distribution(values: Sequence[float], scale: float = 1.0
                      ) -> UserDistribution | None:
    """The per-user figure's numbers of one metric's values (each user's own; None and the
    non-finite values left out, as :func:`.figure_style._finite` does) times ``scale``; None
    when none is left. At most 30 distinct values are drawn as a bar each, more as a
    histogram."""
    import numpy as np

    # numpy throughout (no list of float objects: 100,000 users' values)
    data = np.asarray(values, dtype=float)
    arr = data[np.isfinite(data)] * scale
    del data
    if not arr.size:
        return None
    distinct = np.unique(arr)
    if distinct.size <= 30:
        kind = "bars"
        xs = tuple(float(v) for v in distinct)
        counts = tuple(int(np.sum(arr == v)) for v in distinct)
    else:
        kind = "hist"
        tops, edges = np.histogram(arr, bins="auto")
        xs = tuple(float(e) for e in edges)
        counts = tuple(int(c) for c in tops)
    return UserDistribution(kind, xs, counts, float(arr.min()), float(arr.max()),
                            float(arr.mean()), int(arr.size))


@queueable
def per_user_figure(series: Mapping[str, Sequence[float] | UserDistribution | None],
                    path: Path, *, units: Mapping[str, str] | None = None) -> Path:
    """How users differ: per metric, a histogram of each user's own value (their rate, their
    mean duration), each in its own panel and scale, the mean over users marked.
    ``units`` per metric: ``"%"`` draws a proportion as a percentage, another unit labels
    the axis. A metric's values may come as their :func:`user_distribution` (scaled as its
    unit says): the figure then holds a few numbers per metric, not every user's value."""
    title = "How users differ"
    units = units or {}
    present: dict[str, UserDistribution] = {}
    for name, values in series.items():
        scale = 100.0 if units.get(name, "") == "%" else 1.0
        shown = (values if isinstance(values, UserDistribution) or values is None
                 else user_distribution(values, scale))
        if shown is not None:
            present[name] = shown
    if not present:
        return _empty(path, title)
    with _figure(9.0, 0.9 + 2.0 * len(present)) as fig:
        axes = _panels(fig, len(present), sharex=False)
        for ax, (name, shown) in zip(axes, present.items(), strict=True):
            unit = units.get(name, "")
            scale = 100.0 if unit == "%" else 1.0
            if shown.kind == "bars":
                # a few values (0, 1 of 28 doses, 2 of 28 …): each value users had is a
                # thin bar of its own at that value, not a bin around it (a bin's width
                # would claim values nobody can have, below 0 % or above 100 %)
                counts = list(shown.counts)
                ax.vlines(list(shown.xs), 0, counts, colors=PALETTE[0], linewidth=5,
                          clip_on=False)
                # each bar's number of users above it: one user at 7 % next to 180 at 0 %
                # is a bar too short to see, and a reader should not have to guess it
                for value, count in zip(shown.xs, counts, strict=True):
                    ax.annotate(f"{count}", (value, count), xytext=(0, 2),
                                textcoords="offset points", ha="center", va="bottom",
                                fontsize=8)
                ax.set_ylim(0, max(counts) * 1.2)
                # the y axis set off to the left: a bar at the axis' lowest value (most
                # users at 0 %) is otherwise drawn under the axis line and cannot be seen,
                # and widening the axis instead would show a rate below 0 %
                ax.spines["left"].set_position(("outward", 8))
            else:               # one outlined patch, not a rectangle per bin
                edges = list(shown.xs)
                ax.hist(edges[:-1], bins=edges, weights=list(shown.counts),
                        histtype="stepfilled", color=PALETTE[5], edgecolor=PALETTE[0],
                        linewidth=0.8)
            if unit == "%":     # a rate's axis stays within [0, 100] %
                low, high = shown.low, shown.high
                pad = max((high - low) * 0.05, 0.5)
                ax.set_xlim(max(0.0, low - pad), min(100.0, high + pad))
            mean = shown.mean
            label = _fmt(mean / scale, unit == "%", "" if unit == "%" else unit)
            # the mean in the panel's title, not in a legend box: a box in a corner hid the
            # tallest bar when most users sit at one end (a taken rate near 100 %)
            ax.axvline(mean, color=PALETTE[1], linewidth=1.8, linestyle="--")
            ax.set_title(f"{_text(name)}: mean over users {label} (dashed line)", loc="left",
                         fontsize=11)
            ax.set_ylabel("users")
            ax.set_xlabel(f"each user's {_text(name)}"
                          + (f" ({'%' if unit == '%' else unit})" if unit else ""))
        return figure_files.save(fig, path)


def _step_histograms(ax: Axes, groups: Mapping[str, Sequence[float]], scale: float) -> None:
    """One outline histogram per group on common bins, as the share of the group's users
    (groups of different sizes compare), each group its own colour and line style."""
    import numpy as np

    everything = np.concatenate([np.asarray(v, dtype=float) for v in groups.values()]) * scale
    distinct = np.unique(everything)
    step = float(np.min(np.diff(distinct))) if distinct.size > 1 else 1.0
    if distinct.size <= 30 and (distinct[-1] - distinct[0]) / step <= 200:
        # a few values on a lattice (k/120 of a rate): one even bin per lattice point
        edges = np.arange(distinct[0] - step / 2, distinct[-1] + step, step)
    else:
        edges = np.histogram_bin_edges(everything, bins="auto")
    for i, (name, values) in enumerate(groups.items()):
        arr = np.asarray(values, dtype=float) * scale
        ax.hist(arr, bins=edges.tolist(), weights=np.full(arr.size, 1.0 / max(arr.size, 1)),
                histtype="step", linewidth=1.8, color=PALETTE[i % len(PALETTE)],
                linestyle=_LINESTYLES[i % len(_LINESTYLES)],
                label=f"{_text(name)} ({arr.size} users)")
    ax.set_ylabel("share of the group's users")


@queueable
def subgroups_figure(metric: str, groups: Mapping[str, Sequence[float]], path: Path, *,
                     unit: str = "") -> Path:
    """The distribution over users of each user's own value of ``metric`` (their missed
    rate), one outline histogram per subgroup (and all users), as shares of each group's
    users. ``unit`` ``"%"`` draws a proportion as a percentage."""
    title = f"{metric}: each user's own value, by subgroup"
    present = {name: _finite(values)[0] for name, values in groups.items()}
    present = {name: values for name, values in present.items() if values}
    if not present:
        return _empty(path, _text(title))
    scale = 100.0 if unit == "%" else 1.0
    with _figure(9.0, 3.8) as fig:
        ax = fig.add_subplot()
        _step_histograms(ax, present, scale)
        ax.set_xlabel(f"each user's {_text(metric)}"
                      + (f" ({'%' if unit == '%' else unit})" if unit else ""))
        _outside_legend(ax)
        return figure_files.save(fig, path)


@queueable
def parameters_figure(parameters: Mapping[str, Mapping[str, Sequence[float]]], path: Path
                      ) -> Path:
    """Who the simulated users are: per drawn parameter (a panel each, its own scale), the
    values drawn for the users of each subgroup."""
    title = "Parameters drawn per user"
    present = {name: {g: _finite(v)[0] for g, v in groups.items() if _finite(v)[0]}
               for name, groups in parameters.items()}
    present = {name: groups for name, groups in present.items() if groups}
    if not present:
        return _empty(path, title)
    with _figure(9.0, 0.9 + 2.3 * len(present)) as fig:
        for ax, (name, groups) in zip(_panels(fig, len(present), sharex=False),
                                      present.items(), strict=True):
            _step_histograms(ax, groups, 1.0)
            ax.set_title(_text(name), loc="left", fontsize=11)
            _outside_legend(ax)
        return figure_files.save(fig, path)

