"""The evaluation's figures: one per function, fit for a paper and readable by people who did
not run it.

Every function draws one figure, writes it to ``path`` (parent folders are created) in the
format :func:`figure_format` chose, else the one ``path``'s suffix names — SVG (vector: the
report inlines it; the report's default), PDF, or PNG at :data:`DPI` — and returns the path
written (with PDF, an SVG twin beside it, which is returned: the HTML report shows that one). Empty input never raises: the figure then says "no observations", so a
report of a run in which nothing happened still has all its pictures. Non-finite values
(NaN, ±inf) are left out and counted in the figure's note.

Conventions, so every figure reads the same way:

- colours from the Okabe-Ito palette (distinguishable with the common colour-vision
  deficiencies), and each series also differs by marker or line style, never by colour alone;
- axis labels are words with units (seconds, %, count); a figure has no title: the report's
  caption says what the reader sees (a journal sets its own), panels are labelled on their
  axes;
- rates whose estimates and intervals all lie in [0, 1] are shown as percentages, on axes
  that never leave [0, 100] %.

matplotlib is imported inside the functions, so ``import opspec.evaluation`` stays light. We
draw on :class:`matplotlib.figure.Figure` objects with the Agg canvas instead of pyplot: no
global figure registry (nothing leaks across thousands of calls, and the functions are safe
in worker threads), and no GUI backend is ever chosen.
"""

from __future__ import annotations

import contextlib
import functools
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.errors import EvaluationError
from opspec.evaluation.matplotlib_import import import_matplotlib as _import_matplotlib

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "DPI",
    "FORMATS",
    "PALETTE",
    "activity_rates_figure",
    "comparison_figure",
    "drawing_processes",
    "drawn_by",
    "figure_format",
    "latency_figure",
    "over_days_figure",
    "parameters_figure",
    "per_user_figure",
    "rates_figure",
    "subgroups_figure",
    "sweep_figure",
    "time_of_day_figure",
    "user_distribution",
    "UserDistribution",
]

#: Resolution of PNG figures (journals ask for at least 200-300 dpi for line art in raster).
DPI = 200
#: What ``opspec evaluate --figures`` can write: vector SVG (the default; inlined in the HTML
#: report), vector PDF (for LaTeX), or PNG at :data:`DPI`.
FORMATS = ("svg", "pdf", "png")
#: The format :func:`figure_format` chose; None: the one ``path``'s suffix names (PNG for an
#: unknown suffix).
_FORMAT: ContextVar[str | None] = ContextVar("opspec_figure_format", default=None)
#: A figure asked for within :func:`drawn_by`: the figure function (undecorated), its
#: arguments and the format it is to be written in.
_Job = tuple[Any, tuple[Any, ...], dict[str, Any], str | None]
#: Within :func:`drawn_by`: the figures asked for, drawn at the block's end.
_QUEUE: ContextVar[list[_Job] | None] = ContextVar("opspec_figure_queue", default=None)

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
}

NO_OBSERVATIONS = "no observations"


# --------------------------------------------------------------------------------- helpers

#: the percent sign as the tables write it ("99.61 %"): after a space, on the axes too
PERCENT = " %"


@contextmanager
def figure_format(name: str) -> Iterator[None]:
    """Within this block, figures are written as ``name`` (one of :data:`FORMATS`)."""
    if name not in FORMATS:
        raise EvaluationError(f"unknown figure format {name!r}",
                              hint="use " + ", ".join(FORMATS))
    token = _FORMAT.set(name)
    try:
        yield
    finally:
        _FORMAT.reset(token)


@contextmanager
def drawing_processes(workers: int) -> Iterator[None]:
    """Start up to ``workers`` drawing processes now, for the :func:`drawn_by` blocks within
    this one: each imports matplotlib (and loads its font) while this process still works
    out what to draw. ``opspec evaluate --workers W`` starts them before its replications,
    so that matplotlib is ready when the first figure is asked for: its import (0.3 CPU-s
    in each process) shares the cores with the replications' chunks, which any core can
    run, instead of delaying the figures after them. Nothing happens with one worker or
    where processes cannot be forked.

    Within :func:`staggered_start` only that many are forked now, the others when
    :func:`warm_up_the_rest` is called or the first figure is sent. A failure or Ctrl-C
    within the block ends the processes at once, without waiting for their import."""
    import os

    if workers <= 1 or not hasattr(os, "fork") or _POOL.get() is not None:
        yield
        return
    import multiprocessing

    first = _FIRST.get()
    pools = _Pools(multiprocessing.get_context("fork"), os.getpid(), workers,
                   workers if first is None else min(workers, max(1, first)))
    try:
        pools.start_first()                 # forks them now (not at the first figure)
    except Exception:  # noqa: BLE001 - no processes: the figures are drawn as before
        pools.end_now()                     # those forked before the failure, if any
        yield
        return
    token = _POOL.set((pools, workers))
    try:
        yield
    except BaseException:
        # the command failed or was stopped (a bad spec, Ctrl-C): nothing more to draw, and
        # a process still importing matplotlib is not waited for (the error is shown now)
        pools.end_now()
        raise
    finally:
        _POOL.reset(token)
        pools.shutdown(wait=True, cancel_futures=True)


@contextmanager
def staggered_start(first: int) -> Iterator[None]:
    """Within this block :func:`drawing_processes` forks only ``first`` processes at once;
    the others when :func:`warm_up_the_rest` is called or the first figure is sent.
    ``opspec evaluate`` starts its drawing processes before it loads the spec, whose
    start-up leaves every core but one idle: as many processes as those cores import
    matplotlib then, without slowing that start-up (nor a bad input's error); the others,
    forked as the replications start, inherit what the start-up loaded (NumPy, importlib's
    metadata: 0.1 CPU-s of each one's import)."""
    token = _FIRST.set(first)
    try:
        yield
    finally:
        _FIRST.reset(token)


#: Within :func:`staggered_start`: how many drawing processes are forked at once.
_FIRST: ContextVar[int | None] = ContextVar("opspec_drawing_first", default=None)


def warm_up_the_rest() -> None:
    """Fork the drawing processes of :func:`drawing_processes` not forked yet (past
    :func:`staggered_start`'s ``first``), to import matplotlib now."""
    started = _POOL.get()
    if started is not None:
        started[0].start_rest()


class _Pools:
    """The drawing processes of :func:`drawing_processes` as one executor: ``first`` of the
    ``workers`` forked by :meth:`start_first`, the others by :meth:`start_rest` (or the
    first figure sent); each figure goes to the pool with the fewest figures per process
    still to draw."""

    def __init__(self, context: Any, parent: int, workers: int, first: int) -> None:
        self._context, self._parent = context, parent
        self._sizes = [first, workers - first]
        self._pools: list[Any] = []
        self._sent: list[list[Any]] = []

    def _start(self, size: int) -> None:
        import concurrent.futures as cf

        pool = cf.ProcessPoolExecutor(max_workers=size, initializer=_warm_up,
                                      initargs=(self._parent,), mp_context=self._context)
        self._pools.append(pool)
        self._sent.append([])
        for _ in range(size):               # a fork context forks them all at the first
            pool.submit(_ready)

    def start_first(self) -> None:
        self._start(self._sizes[0])

    def start_rest(self) -> None:
        if len(self._pools) == 1 and self._sizes[1] > 0:
            try:
                self._start(self._sizes[1])
            except Exception:  # noqa: BLE001, S110 - the first ones draw every figure
                self._sizes[1] = 0

    def submit(self, fn: Callable[..., Any], /, *args: Any) -> Any:
        self.start_rest()
        live = [i for i in range(len(self._pools)) if self._sizes[i] > 0]
        i = min(live, key=lambda k: sum(not f.done() for f in self._sent[k]) / self._sizes[k])
        future = self._pools[i].submit(fn, *args)
        self._sent[i].append(future)
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        for pool in self._pools:
            pool.shutdown(wait=wait, cancel_futures=cancel_futures)

    def end_now(self) -> None:
        """End every drawing process without waiting for its work, and then each pool's
        managing thread."""
        # the executor keeps its processes in a private field (terminate_workers: Python
        # 3.14), which shutdown empties
        processes = [process for pool in self._pools
                     for process in (getattr(pool, "_processes", None) or {}).values()]
        for process in processes:
            with contextlib.suppress(Exception):
                process.terminate()
        for process in processes:            # gone before the error is shown
            with contextlib.suppress(Exception):
                process.join(5)
                if process.is_alive():
                    process.kill()
                    process.join(5)
        # With its processes gone, each pool's managing thread finds the pool broken and
        # ends, closing its wake-up pipe; waiting for that here matters: at the
        # interpreter's exit Python 3.11 wakes every such thread without a lock, and one
        # closing its pipe at that moment printed "Bad file descriptor" and a traceback
        # after the error (CPython gh-84176; later 3.12 and 3.13 releases lock it, gh-125451)
        self.shutdown(wait=True, cancel_futures=True)


#: Within :func:`drawing_processes`: its processes (:class:`_Pools`) and how many.
_POOL: ContextVar[tuple[Any, int] | None] = ContextVar("opspec_drawing_pool", default=None)


def _warm_up(parent: int) -> None:
    """A drawing process's start: Ctrl-C left to the evaluate process (which stops the
    pool; no traceback from each drawing process), an end of its own when that process is
    gone (killed: it cannot stop the pool, and a drawing process waiting for figures would
    live on), matplotlib imported, its default font found and loaded."""
    import os
    import signal
    import threading
    import time

    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="opspec-drawing-watch", daemon=True).start()
    try:
        _import_matplotlib()
        from matplotlib import font_manager
        from matplotlib.ft2font import FT2Font

        FT2Font(font_manager.findfont(font_manager.FontProperties()))
    except Exception:  # noqa: BLE001, S110 - a figure drawn later says what is wrong
        pass


def _ready() -> None:
    """The task that makes the pool fork its processes."""


@contextmanager
def drawn_by(workers: int) -> Iterator[None]:
    """Within this block, the figure functions return the path they will write at once and
    the figures are drawn at the block's end, by up to ``workers`` processes side by side
    (each figure is independent of the others; the same bytes as drawn one after another),
    those of an enclosing :func:`drawing_processes` when there is one. With one worker
    they are drawn as they are asked for (nothing queued). ``opspec evaluate --workers W``
    draws its report's figures so: what runs after the replications runs on one core
    otherwise, and with two workers it was most of the wall time saved."""
    if workers <= 1:                # drawn as they are asked for, as without this block
        yield
        return
    queue: list[_Job] = []
    # with started drawing processes, each figure is sent to them as it is asked for: they
    # draw while this process still works out the report's other figures and tables
    sent: dict[int, Any] | None = {} if _POOL.get() is not None else None
    token, sending = _QUEUE.set(queue), _SENT.set(sent)
    try:
        yield
    finally:
        _QUEUE.reset(token)
        _SENT.reset(sending)
    _draw(queue, workers, sent or {})


#: Within :func:`drawn_by` with started drawing processes: the futures of the figures sent
#: to them as they were asked for, by their place in the queue.
_SENT: ContextVar[dict[int, Any] | None] = ContextVar("opspec_figures_sent", default=None)


def _send_now(queue: Sequence[_Job], sent: dict[int, Any]) -> None:
    """Send the figure last queued to the started drawing processes, when they know its
    function; otherwise it waits for the block's end (:func:`_draw`)."""
    started = _POOL.get()
    draw, args, kwargs, fmt = queue[-1]
    name = getattr(draw, "__name__", "")
    if started is None or _FIGURES.get(name) is not draw:
        return
    try:
        sent[len(queue) - 1] = started[0].submit(_draw_named, name, args, kwargs, fmt)
    except Exception:  # noqa: BLE001, S110 - a process gone: drawn at the block's end
        pass


def _draw(queue: Sequence[_Job], workers: int, sent: Mapping[int, Any] | None = None
          ) -> None:
    global _JOBS
    sent = sent or {}
    if workers > 1 and (len(queue) > 1 or sent):
        started = _POOL.get()
        if started is not None and _on_started(started[0], queue, sent):
            return
        import concurrent.futures as cf
        import multiprocessing
        import os

        if hasattr(os, "fork"):
            # the processes are forked with the queue in place: only its indexes travel
            _JOBS = queue
            drawn = False
            try:
                with cf.ProcessPoolExecutor(
                        max_workers=min(workers, len(queue)),
                        mp_context=multiprocessing.get_context("fork")) as pool:
                    list(pool.map(_draw_job, range(len(queue))))
                drawn = True
            except Exception:  # noqa: BLE001 - drawn again below, where an error is plain
                drawn = False
            finally:
                _JOBS = ()
            if drawn:
                return
    for job in queue:
        _draw_one(job)


def _on_started(pool: Any, queue: Sequence[_Job], sent: Mapping[int, Any]) -> bool:
    """Draw ``queue`` on the processes :func:`drawing_processes` started, the figure
    functions sent by name (they were forked before the figures were asked for); those
    ``sent`` as they were asked for are only waited for. False when that cannot be done (a
    figure function replaced by another, a process gone, a figure that failed): the caller
    draws them as before, where an error is plain."""
    import concurrent.futures as cf

    futures = list(sent.values())
    try:
        for index, (draw, args, kwargs, fmt) in enumerate(queue):
            if index in sent:
                continue
            name = getattr(draw, "__name__", "")
            if _FIGURES.get(name) is not draw:
                return False
            futures.append(pool.submit(_draw_named, name, args, kwargs, fmt))
    except Exception:  # noqa: BLE001 - a process gone: drawn again by the caller
        return False
    finally:
        # every figure sent is finished before the caller may draw it again
        cf.wait(futures)
    return all(future.exception() is None for future in futures)


#: Every figure function (undecorated), by name: what a started drawing process is sent.
_FIGURES: dict[str, Any] = {}


def _draw_named(name: str, args: tuple[Any, ...], kwargs: dict[str, Any], fmt: str | None
                ) -> None:
    _draw_one((_FIGURES[name], args, kwargs, fmt))


#: The queue :func:`_draw` hands to the processes it forks.
_JOBS: Sequence[_Job] = ()


def _draw_job(index: int) -> None:
    _draw_one(_JOBS[index])


def _draw_one(job: _Job) -> None:
    _import_matplotlib()
    draw, args, kwargs, fmt = job
    if fmt is None:
        draw(*args, **kwargs)
        return
    with figure_format(fmt):
        draw(*args, **kwargs)


def _written(path: Path) -> tuple[Path, str]:
    """The file a figure asked to be written at ``path`` is written to, and its format."""
    fmt = _FORMAT.get() or (Path(path).suffix.lstrip(".").lower() or "png")
    if fmt not in FORMATS:
        fmt = "png"
    return Path(path).with_suffix(f".{fmt}"), fmt


_Draw = Callable[..., Path]


def _queueable(draw: _Draw) -> _Draw:
    """A figure function that, within :func:`drawn_by`, queues the figure and returns the
    path it returns once drawn (with PDF, the SVG twin's)."""
    import inspect

    signature = inspect.signature(draw)
    _FIGURES[draw.__name__] = draw

    @functools.wraps(draw)
    def figure(*args: Any, **kwargs: Any) -> Path:
        queue = _QUEUE.get()
        if queue is None:
            # before the figure's own imports of matplotlib's parts (its ticker, say)
            _import_matplotlib()
            return draw(*args, **kwargs)
        queue.append((draw, args, kwargs, _FORMAT.get()))
        sent = _SENT.get()
        if sent is not None:
            _send_now(queue, sent)
        path, fmt = _written(signature.bind(*args, **kwargs).arguments["path"])
        return path.with_suffix(".svg") if fmt == "pdf" else path

    return figure


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


def _save(fig: Figure, path: Path) -> Path:
    path, fmt = _written(path)
    _lay_out(fig)
    fig.patch.set_facecolor("white")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        if fmt == "png":
            _save_png(fig, path)
            return path
        # no dates in the files: the same results give the same bytes
        fig.savefig(path, format=fmt, metadata={"Date": None} if fmt == "svg"
                    else {"CreationDate": None, "ModDate": None})
        if fmt == "pdf":            # the HTML report shows vector figures inline: SVG
            twin = path.with_suffix(".svg")
            fig.savefig(twin, format="svg", metadata={"Date": None})
            return twin
    except OSError as error:
        raise EvaluationError(f"cannot write the figure {path}: {error.strerror or error}",
                              hint="check that the output folder exists, is writable and "
                                   "the disk is not full") from None
    return path


def _lay_out(fig: Figure) -> None:
    """Place the panels so that every text fits: from the texts' measured sizes
    (:mod:`.figure_layout`), or with matplotlib's constrained layout for a figure that
    module does not lay out. Either is done once, before the drawing, which then lays
    nothing out again."""
    from opspec.evaluation.figure_layout import lay_out

    if not lay_out(fig):
        from matplotlib.layout_engine import ConstrainedLayoutEngine

        ConstrainedLayoutEngine().execute(fig)


def _save_png(fig: Figure, path: Path) -> None:
    from PIL import Image

    canvas = fig.canvas
    canvas.draw()
    width, height = canvas.get_width_height(physical=True)
    # RGB rather than matplotlib's RGBA (the background is opaque white: a quarter less to
    # compress), at zlib level 3: half the encoding time of level 6, and files no larger
    # than matplotlib's own RGBA at level 6. The resolution is stored (pHYs) for layout tools.
    image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(),  # type: ignore[attr-defined]
                             "raw", "RGBA", 0, 1).convert("RGB")
    image.save(path, format="png", compress_level=3, dpi=(DPI, DPI))


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
        return _save(fig, path)


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


def _outside_legend(ax: Axes) -> None:
    """The legend to the right of the plot, where it never hides a line."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def _bar_height(rows: int) -> float:
    """Figure height (inches) for one horizontal row per item, within sane bounds."""
    return min(2.0 + 0.45 * rows, 24.0)


# --------------------------------------------------------------------------------- figures

@_queueable
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
        return _save(fig, path)


def _panels(fig: Figure, n: int, *, sharex: bool = True) -> list[Axes]:
    """``n`` stacked panels, each with its own vertical scale."""
    axes = fig.subplots(n, 1, squeeze=False, sharex=sharex)[:, 0]
    return list(axes)


@_queueable
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
            if percent:
                from matplotlib.ticker import PercentFormatter

                left, right = max(left, 0.0), min(right, 1.0)
                step = max((right - left) * 100.0 / 6.0, 1e-9)   # about six ticks
                ax.xaxis.set_major_formatter(PercentFormatter(
                    xmax=1.0, decimals=max(0, -math.floor(math.log10(step))), symbol=PERCENT))
            ax.set_xlim(left, right)
            ax.xaxis.set_major_locator(MaxNLocator(6))
        if all(_is_rate([e, lo, hi]) for _, e, lo, hi in clean):
            fig.supxlabel("rate (% of opportunities)", fontsize=11)
        _note_dropped(fig, dropped)
        return _save(fig, path)


@_queueable
def over_days_figure(series: Mapping[str, Sequence[float]], path: Path, *,
                     bands: Mapping[str, Sequence[tuple[float | None, float | None]]]
                     | None = None) -> Path:
    """One panel per metric, each on its own scale: its value on day 1, 2, …, D, with the
    95 % interval of each day as a band when ``bands`` gives them (per metric, per day)."""
    bands = {_text(name): list(b) for name, b in (bands or {}).items()}
    title = "Outcomes over the simulated days"
    present = {_text(name): list(vals) for name, vals in series.items() if len(vals) > 0}
    never = [name for name, vals in present.items() if all(v == 0 for v in vals)]
    present = {name: vals for name, vals in present.items() if name not in never}
    if not present:
        return _empty(path, title + (": every outcome was 0 on every day" if never else ""))
    longest = max(len(v) for v in present.values())
    with _figure(9.0, 0.9 + 1.45 * len(present)) as fig:
        _note(fig, _never(never))
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
            ax.set_ylabel(f"{name}\n(per user)", rotation=0, ha="right", va="center")
            finite = [y for y in ys_all if math.isfinite(y)]
            if finite and min(finite) >= 0:
                ax.set_ylim(bottom=0, top=max(max(finite) * 1.15, 1e-9))
        axes[-1].set_xlabel("simulated day")
        axes[-1].set_xlim(0.5, longest + 0.5)
        if longest <= 10:
            axes[-1].set_xticks(range(1, longest + 1))
        elif longest <= 31:     # day 1 and every fifth: a grid a reader counts along
            axes[-1].set_xticks([1, *range(5, longest + 1, 5)])
        return _save(fig, path)


@_queueable
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
        return _save(fig, path)


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
    non-finite values left out, as :func:`_finite` does) times ``scale``; None when none
    is left. At most 30 distinct values are drawn as a bar each, more as a histogram."""
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


@_queueable
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
        return _save(fig, path)


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


@_queueable
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
        return _save(fig, path)


@_queueable
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
        return _save(fig, path)


@_queueable
def activity_rates_figure(rows: Sequence[tuple[Any, ...]], path: Path) -> Path:
    """Grouped horizontal bars: omission rate and error rate of each (manual) activity,
    ``(activity, omission, error)`` or, with their 95 % intervals drawn as error bars,
    ``(activity, omission, error, (low, high), (low, high))``."""
    title = "Omission and error rates per activity"
    clean = [(_text(r[0]), float(r[1]), float(r[2])) for r in rows
             if math.isfinite(float(r[1])) and math.isfinite(float(r[2]))]
    intervals = [(r[3], r[4]) for r in rows if len(r) == 5
                 and math.isfinite(float(r[1])) and math.isfinite(float(r[2]))]
    dropped = len(rows) - len(clean)
    if not clean:
        return _empty(path, title)
    percent = _is_rate([v for _, o, e in clean for v in (o, e)])
    with _figure(8.5, _bar_height(int(1.5 * len(clean)) + 1)) as fig:
        ax = fig.add_subplot()
        n = len(clean)
        centres = list(range(n))[::-1]
        height = 0.38
        omission = ax.barh([c + height / 2 for c in centres], [o for _, o, _ in clean],
                           height=height, color=PALETTE[1], edgecolor="black", linewidth=0.5,
                           label="omission rate (not done)")
        error = ax.barh([c - height / 2 for c in centres], [e for *_, e in clean],
                        height=height, color=PALETTE[0], edgecolor="black", linewidth=0.5,
                        hatch="//", label="error rate (done wrongly)")
        tops = [max(o, e) for _, o, e in clean]
        ends = [[b.get_width() for b in omission], [b.get_width() for b in error]]
        if len(intervals) == n:
            for offset, k in ((height / 2, 0), (-height / 2, 1)):
                ests = [clean[i][1 + k] for i in range(n)]
                lows = [max(0.0, ests[i] - (intervals[i][k][0] or 0.0)) for i in range(n)]
                highs = [max(0.0, (intervals[i][k][1] or 0.0) - ests[i]) for i in range(n)]
                ax.errorbar(ests, [c + offset for c in centres], xerr=[lows, highs],
                            fmt="none", ecolor="black", capsize=3, linewidth=1.0)
            tops = [max(o, e, intervals[i][0][1] or 0.0, intervals[i][1][1] or 0.0)
                    for i, (_, o, e) in enumerate(clean)]
            ends = [[max(clean[i][1 + k], intervals[i][k][1] or 0.0) for i in range(n)]
                    for k in (0, 1)]
        # each value just past its bar, or past its interval when it has one
        for bars, at in zip((omission, error), ends, strict=True):
            for bar, x in zip(bars, at, strict=True):
                ax.annotate(_fmt(bar.get_width(), percent),
                            (x, bar.get_y() + bar.get_height() / 2), xytext=(4, 0),
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
        return _save(fig, path)


@_queueable
def comparison_figure(rows: Sequence[tuple[str, float, float, float]], path: Path,
                      units: Mapping[str, str] | None = None) -> Path:
    """Each ``(metric, difference B − A, ci_low, ci_high)`` in its own panel with its own
    scale and a zero line (metrics differ in unit and size: one shared axis would flatten a
    rate's ±0.005 next to a latency's −40 s). ``units`` per metric: ``"pp"`` draws a rate's
    difference in percentage points, other units label the axis.

    Differences whose interval excludes zero are drawn filled; the others hollow.
    """
    title = "Design B minus design A, with 95 % confidence intervals"
    clean = [(_text(m), float(d), float(lo), float(hi)) for m, d, lo, hi in rows
             if all(v is not None and math.isfinite(float(v)) for v in (d, lo, hi))]
    dropped = len(rows) - len(clean)
    if not clean:
        return _empty(path, title)
    units = units or {}
    with _figure(9.0, 0.9 + 0.75 * len(clean)) as fig:
        axes = fig.subplots(len(clean), 1, squeeze=False)[:, 0]
        for ax, (name, diff, lo, hi) in zip(axes, clean, strict=True):
            unit = units.get(name, "")
            scale = 100.0 if unit == "pp" else 1.0
            diff, lo, hi = diff * scale, lo * scale, hi * scale
            significant = lo > 0.0 or hi < 0.0
            colour = PALETTE[4] if significant else PALETTE[0]
            ax.axvline(0.0, color="black", linewidth=1.0, linestyle="--")
            ax.errorbar([diff], [0.0], xerr=[[max(diff - lo, 0.0)], [max(hi - diff, 0.0)]],
                        fmt="D" if significant else "o", color=colour, ecolor=colour,
                        markerfacecolor=colour if significant else "white", capsize=5,
                        markersize=7, linewidth=1.8)
            suffix = f" {unit}" if unit else ""
            ax.annotate(f"{diff:+.4g}{suffix}  [{lo:+.4g}, {hi:+.4g}]", (hi, 0.0),
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
        _note_dropped(fig, dropped)
        return _save(fig, path)


@_queueable
def sweep_figure(parameter: str, xs: Sequence[float], labels: Sequence[str],
                 series: Mapping[str, tuple[Sequence[float | None], Sequence[float | None],
                                            Sequence[float | None]]],
                 path: Path, *, percent: Mapping[str, bool] | None = None,
                 units: Mapping[str, str] | None = None,
                 targets: Mapping[str, Sequence[tuple[str, float]]] | None = None,
                 per_user: Mapping[str, tuple[str, Sequence[float | None]]] | None = None
                 ) -> Path:
    """Each metric of a sweep against the swept parameter (``opspec evaluate --sweep``): per
    metric ``(estimates, ci lows, ci highs)``, one per value at ``xs`` (tick ``labels`` as the
    values read), each metric in its own panel with its own scale; the estimate as a line with
    markers, its 95 % interval as a band. ``targets`` draws each target's threshold on its
    metric's panel (dashed), ``per_user`` a per-user quantile (dotted) that a share-of-users
    target is judged by."""
    title = f"Metrics against {parameter}"
    names = [n for n, (est, _, _) in series.items()
             if any(e is not None and math.isfinite(float(e)) for e in est)]
    if not names or not xs:
        return _empty(path, title)
    percent, units = percent or {}, units or {}
    targets, per_user = targets or {}, per_user or {}
    with _figure(9.0, 1.2 + 2.1 * len(names)) as fig:
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
                                label="95 % interval")
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
        return _save(fig, path)
