"""The look every figure shares, so that they all read the same way, and the small pieces
the figure functions (:mod:`.outcome_figures`, :mod:`.user_figures`,
:mod:`.comparison_figures`) draw with; those pieces are theirs alone, hence the leading
underscores.

- colours from the Okabe-Ito palette (distinguishable with the common colour-vision
  deficiencies), and each series also differs by marker or line style, never by colour alone;
- axis labels are words with units (seconds, %, count); a figure has no title: the report's
  caption says what the reader sees (a journal sets its own), panels are labelled on their
  axes;
- rates whose estimates and intervals all lie in [0, 1] are shown as percentages, on axes
  that never leave [0, 100] %;
- empty input never raises: the figure then says "no observations"; non-finite values (NaN,
  ±inf) are left out and counted in the figure's note.

We draw on :class:`matplotlib.figure.Figure` objects with the Agg canvas instead of pyplot: no
global figure registry (nothing leaks across thousands of calls, and the functions are safe
in worker threads), and no GUI backend is ever chosen.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.evaluation import figure_files
from opspec.evaluation.figure_files import DPI
from opspec.evaluation.matplotlib_import import import_matplotlib as _import_matplotlib

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["NO_OBSERVATIONS", "PALETTE", "PERCENT"]

#: Okabe & Ito (2008), "Color Universal Design": safe for deuteranopia, protanopia, tritanopia.
PALETTE: tuple[str, ...] = (
    "#0072B2",  # blue
    "#E69F00",  # orange
    "#009E73",  # bluish green
    "#CC79A7",  # reddish purple
    "#D55E00",  # vermillion
    "#56B4E9",  # sky blue
    "#F0E442",  # yellow (last: low contrast on white)
    "#000000",  # black
)
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
_LINESTYLES = ("-", "--", "-.", ":")

_RC: dict[str, Any] = {
    "font.size": 11,
    "axes.titlesize": 12,
    "axes.labelsize": 11,
    "xtick.labelsize": 10,
    "ytick.labelsize": 10,
    "legend.fontsize": 10,
    "figure.titlesize": 13,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "svg.hashsalt": "opspec",   # the same ids in every run: the report's bytes are reproducible
    # texts as <text> in the font stack DejaVu Sans, ..., sans-serif, not as glyph outlines:
    # a reader can select and search them (in the report too), a journal's editor can fix a
    # word, and writing outlines was a sixth of the report's drawing time (PDF embeds its fonts)
    "svg.fonttype": "none",
    # PDF embeds its fonts as TrueType (Type 42), not Type 3: publishers' PDF checks (IEEE
    # PDF eXpress, ACM's) refuse a paper whose figures carry Type 3 fonts
    "pdf.fonttype": 42,
}

NO_OBSERVATIONS = "no observations"

#: the percent sign as the tables write it ("99.61 %"): after a space, on the axes too
PERCENT = " %"


@contextmanager
def _figure(width: float, height: float) -> Iterator[Figure]:
    """A fresh Agg-backed figure under opspec's style (fonts, grid, palette)."""
    _import_matplotlib()
    import matplotlib
    from cycler import cycler
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rc = {**_RC, "axes.prop_cycle": cycler(color=PALETTE)}
    with matplotlib.rc_context(rc):  # type: ignore[arg-type]  # keys are literal rc names
        fig = Figure(figsize=(width, height), dpi=DPI)
        FigureCanvasAgg(fig)
        yield fig



def _finite(values: Sequence[float]) -> tuple[list[float], int]:
    """The finite values as floats, and how many others were dropped."""
    kept = [float(v) for v in values if v is not None and math.isfinite(float(v))]
    return kept, len(values) - len(kept)


def _empty(path: Path, title: str, width: float = 8.0, height: float = 3.2) -> Path:
    """A figure whose only content is its title and the words "no observations"."""
    with _figure(width, height) as fig:
        ax = fig.add_subplot()
        ax.set_axis_off()
        ax.set_title(title)
        ax.text(0.5, 0.5, NO_OBSERVATIONS, ha="center", va="center", fontsize=16,
                color="#444444", transform=ax.transAxes)
        return figure_files.save(fig, path)


def _text(label: object) -> str:
    """A user-supplied name as literal text: a ``$`` would otherwise start mathtext."""
    return str(label).replace("$", r"\$")


def _is_rate(values: Sequence[float]) -> bool:
    return bool(values) and all(0.0 <= v <= 1.0 for v in values)


def _percent_axis(ax: Axes, axis: str = "x") -> None:
    from matplotlib.ticker import PercentFormatter

    target = ax.xaxis if axis == "x" else ax.yaxis
    target.set_major_formatter(PercentFormatter(xmax=1.0, decimals=None, symbol=PERCENT))


def _fmt(value: float, percent: bool, unit: str = "") -> str:
    """A number as the report's tables print it (:func:`.tables.fmt`): the same numbers
    everywhere (tests/evaluation_output/test_figure_numbers.py compares them)."""
    from opspec.evaluation.tables import fmt

    return fmt(float(value), unit, percent=percent)


def _note_dropped(fig: Figure, dropped: int) -> None:
    if dropped:
        fig.text(0.01, 0.005, f"{dropped} non-finite value(s) left out", fontsize=9,
                 color="#444444", ha="left", va="bottom")


def _never(names: Sequence[str]) -> str:
    """A note naming the metrics not drawn because they never happened (a panel of zeros on
    a made-up scale would only look like data)."""
    return f"never happened, so not drawn: {', '.join(names)}" if names else ""


def _note(fig: Figure, text: str) -> None:
    """A small note under the figure (what is not drawn, a sample): part of the figure, as
    the caption cannot know it."""
    if text:
        fig.supxlabel(text, fontsize=9, color="#444444", ha="left", x=0.01)


#: Characters of a note's line per inch of the figure's width: the 9-point notes stay
#: inside the figure (about 5.4 points a character, less the 1 % margin on the left)
_NOTE_CHARACTERS_PER_INCH = 11.5


def _wrapped(text: str | None, width: float) -> str:
    """A note (one of :mod:`.no_spread_notes`') in lines that fit a figure ``width``
    inches wide; the layout makes room under the panels for as many as it takes."""
    import textwrap

    return textwrap.fill(text, int(width * _NOTE_CHARACTERS_PER_INCH)) if text else ""


def _notes(*texts: str) -> str:
    """The notes given, one under the other, for :func:`_note`."""
    return "\n".join(t for t in texts if t)


def _outside_legend(ax: Axes) -> None:
    """The legend to the right of the plot, where it never hides a line."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def _bar_height(rows: int) -> float:
    """Figure height (inches) for one horizontal row per item, within sane bounds."""
    return min(2.0 + 0.45 * rows, 24.0)


def _panels(fig: Figure, n: int, *, sharex: bool = True) -> list[Axes]:
    """``n`` stacked panels, each with its own vertical scale."""
    axes = fig.subplots(n, 1, squeeze=False, sharex=sharex)[:, 0]
    return list(axes)

