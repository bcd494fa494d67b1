"""The figures that compare: design B against design A, each metric's paired difference with
its interval (:func:`comparison_figure`), and each metric against a swept parameter's values
(:func:`sweep_figure`, ``opspec evaluate --sweep``).

Each function draws one figure, writes it to ``path`` (:func:`.figure_files.save`) and
returns the path written; empty input gives a figure that says "no observations".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from opspec.evaluation import figure_files
from opspec.evaluation.figure_queue import queueable
from opspec.evaluation.figure_style import (
    _LINESTYLES,
    PALETTE,
    PERCENT,
    _empty,
    _figure,
    _note,
    _notes,
    _outside_legend,
    _panels,
    _text,
    _wrapped,
)
from opspec.evaluation.no_spread_notes import MARK

__all__ = ["comparison_figure", "sweep_figure"]


@queueable
def comparison_figure(rows: Sequence[tuple[str, float, float | None, float | None]],
                      path: Path, units: Mapping[str, str] | None = None, *,
                      no_interval: Mapping[str, str] | None = None,
                      no_spread: Sequence[str] = (), no_spread_note: str | None = None
                      ) -> Path:
    """Each ``(metric, difference B − A, ci_low, ci_high)`` in its own panel with its own
    scale and a zero line (metrics differ in unit and size: one shared axis would flatten a
    rate's ±0.005 next to a latency's −40 s). ``units`` per metric: ``"pp"`` draws a rate's
    difference in percentage points, other units label the axis. Each label is written as
    the report's table writes it (:func:`.tables.difference_text`: signed, a difference).

    Differences whose interval excludes zero are drawn filled; the others hollow. A
    difference without an interval (``ci_low``, ``ci_high`` None) is not drawn; the figure's
    note names it, with ``no_interval``'s reason for it when given. The metrics in
    ``no_spread`` have an interval of no width because the few users all differed by the
    same amount: it is marked (†) and ``no_spread_note`` says under the figure what that
    means (:mod:`.no_spread_notes`).
    """
    from opspec.evaluation.tables import difference_text

    title = "Design B minus design A, with 95 % confidence intervals"
    clean = [(_text(m), float(d), float(lo), float(hi)) for m, d, lo, hi in rows
             if all(v is not None and math.isfinite(float(v)) for v in (d, lo, hi))]
    bare = [(_text(m), (no_interval or {}).get(m)) for m, d, lo, hi in rows
            if d is not None and math.isfinite(float(d)) and (lo is None or hi is None)]
    dropped = len(rows) - len(clean) - len(bare)
    if not clean:
        return _empty(path, title + (f"\n{_unshown(bare)}" if bare else ""))
    units = units or {}
    alike = {_text(m) for m in no_spread}
    with _figure(9.0, 0.9 + 0.75 * len(clean)) as fig:
        axes = fig.subplots(len(clean), 1, squeeze=False)[:, 0]
        for ax, (name, diff, lo, hi) in zip(axes, clean, strict=True):
            unit = units.get(name, "")
            scale = 100.0 if unit == "pp" else 1.0
            label = (f"{difference_text(diff, unit, percent=unit == 'pp')}  "
                     f"[{difference_text(lo, unit, percent=unit == 'pp')}, "
                     f"{difference_text(hi, unit, percent=unit == 'pp')}]"
                     + (f" {MARK}" if name in alike else ""))
            diff, lo, hi = diff * scale, lo * scale, hi * scale
            significant = lo > 0.0 or hi < 0.0
            colour = PALETTE[4] if significant else PALETTE[0]
            ax.axvline(0.0, color="black", linewidth=1.0, linestyle="--")
            ax.errorbar([diff], [0.0], xerr=[[max(diff - lo, 0.0)], [max(hi - diff, 0.0)]],
                        fmt="D" if significant else "o", color=colour, ecolor=colour,
                        markerfacecolor=colour if significant else "white", capsize=5,
                        markersize=7, linewidth=1.8)
            ax.annotate(label, (hi, 0.0),
                        xytext=(6, 0), textcoords="offset points", va="center", fontsize=9)
            reach = max(abs(lo), abs(hi))
            if reach == 0.0:             # the same for every user: no scale to show
                ax.set_xlim(-1.0, 1.9)
                ax.set_xticks([])
            else:
                ax.set_xlim(-reach * 1.25, reach * 1.9)  # room for the label on the right
            ax.set_yticks([0.0], [f"{name} ({unit})" if unit else name])
            ax.set_ylim(-1.0, 1.0)
            ax.grid(axis="y", visible=False)
        left_out = f"{dropped} non-finite value(s) left out" if dropped else ""
        # one note (two at the foot would overlap)
        foot = _notes(_unshown(bare) + (f"; {left_out}" if left_out else "") if bare
                      else left_out,
                      _wrapped(no_spread_note, 9.0) if alike & {c[0] for c in clean} else "")
        if foot:
            fig.text(0.01, 0.005, foot, fontsize=9, color="#444444", ha="left", va="bottom")
        return figure_files.save(fig, path)


def _unshown(bare: Sequence[tuple[str, str | None]]) -> str:
    """The note naming the differences drawn without an interval, and why each has none."""
    return "not drawn, no 95 % interval: " + "; ".join(
        name + (f" ({why})" if why else "") for name, why in bare)


@queueable
def sweep_figure(parameter: str, xs: Sequence[float], labels: Sequence[str],
                 series: Mapping[str, tuple[Sequence[float | None], Sequence[float | None],
                                            Sequence[float | None]]],
                 path: Path, *, percent: Mapping[str, bool] | None = None,
                 units: Mapping[str, str] | None = None,
                 targets: Mapping[str, Sequence[tuple[str, float]]] | None = None,
                 per_user: Mapping[str, tuple[str, Sequence[float | None]]] | None = None,
                 no_spread: Sequence[str] = (), no_spread_note: str | None = None
                 ) -> Path:
    """Each metric of a sweep against the swept parameter (``opspec evaluate --sweep``): per
    metric ``(estimates, ci lows, ci highs)``, one per value at ``xs`` (tick ``labels`` as the
    values read), each metric in its own panel with its own scale; the estimate as a line with
    markers, its 95 % interval as a band. ``targets`` draws each target's threshold on its
    metric's panel (dashed), ``per_user`` a per-user quantile (dotted) that a share-of-users
    target is judged by. The metrics in ``no_spread`` have a band of no width at some value
    because the few users were all alike: its legend line is marked (†) and
    ``no_spread_note`` says under the figure what that means (:mod:`.no_spread_notes`)."""
    title = f"Metrics against {parameter}"
    names = [n for n, (est, _, _) in series.items()
             if any(e is not None and math.isfinite(float(e)) for e in est)]
    if not names or not xs:
        return _empty(path, title)
    percent, units = percent or {}, units or {}
    targets, per_user = targets or {}, per_user or {}
    alike = set(no_spread) & set(names)
    with _figure(9.0, 1.2 + 2.1 * len(names)) as fig:
        _note(fig, _wrapped(no_spread_note if alike else None, 9.0))
        axes = _panels(fig, len(names), sharex=True)
        for ax, name in zip(axes, names, strict=True):
            est, low, high = series[name]
            scale = 100.0 if percent.get(name) else 1.0
            keep = [i for i, e in enumerate(est) if e is not None and math.isfinite(float(e))]
            x = [xs[i] for i in keep]
            y = [float(est[i]) * scale for i in keep]        # type: ignore[arg-type]
            band = [i for i in keep if low[i] is not None and high[i] is not None]
            if band:
                ax.fill_between([xs[i] for i in band],
                                [float(low[i]) * scale for i in band],   # type: ignore[arg-type]
                                [float(high[i]) * scale for i in band],  # type: ignore[arg-type]
                                color=PALETTE[0], alpha=0.22, linewidth=0,
                                label="95 % interval" + (f" {MARK}" if name in alike
                                                         else ""))
            ax.plot(x, y, marker="o", color=PALETTE[0], linewidth=1.8, label="estimate")
            for i, (text, threshold) in enumerate(targets.get(name, ())):
                ax.axhline(threshold * scale, color=PALETTE[4], linewidth=1.4,
                           linestyle=_LINESTYLES[(i + 1) % len(_LINESTYLES)],
                           label=f"target {_text(text)}")
            if name in per_user:
                text, values = per_user[name]
                points = [(xs[i], float(v) * scale) for i, v in enumerate(values)
                          if v is not None and math.isfinite(float(v))]
                if points:
                    ax.plot([p[0] for p in points], [p[1] for p in points], marker="s",
                            color=PALETTE[2], linestyle=":", linewidth=1.6,
                            label=_text(text))
            unit = "%" if percent.get(name) else units.get(name, "")
            ax.set_ylabel(f"{_text(name)}" + (f"\n({unit})" if unit else ""), fontsize=10)
            if percent.get(name):
                from matplotlib.ticker import PercentFormatter

                ax.yaxis.set_major_formatter(PercentFormatter(xmax=100.0, decimals=None,
                                                              symbol=PERCENT))
            _outside_legend(ax)
        axes[-1].set_xticks(list(xs), [_text(label) for label in labels])
        axes[-1].set_xlabel(_text(parameter))
        return figure_files.save(fig, path)
