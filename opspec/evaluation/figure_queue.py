"""Figures asked for side by side: within :func:`drawn_by` a figure function queues its
figure and returns the path it will write at once; the figures are drawn at the block's end
by worker processes, or sent as they are asked for to the drawing processes already started
(:mod:`.drawing_pools`). Every figure function is made :func:`queueable`, which also
registers it by name in :data:`_FIGURES`: a started drawing process is sent a figure's name
and arguments, never the function. Figures may also be asked for before that block
(:func:`asked_ahead`): the report's that need neither the sample index nor the summaries are
sent as soon as the last replication is stored.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

from opspec.evaluation.drawing_pools import started_pools
from opspec.evaluation.figure_files import chosen_format, figure_format, written_as
from opspec.evaluation.matplotlib_import import import_matplotlib as _import_matplotlib

__all__ = ["FiguresAhead", "asked_ahead", "drawn_by", "queueable"]

#: A figure asked for within :func:`drawn_by`: the figure function (undecorated), its
#: arguments and the format it is to be written in.
_Job = tuple[Any, tuple[Any, ...], dict[str, Any], str | None]
#: Within :func:`drawn_by`: the figures asked for, drawn at the block's end.
_QUEUE: ContextVar[list[_Job] | None] = ContextVar("opspec_figure_queue", default=None)


class FiguresAhead:
    """Figures asked for within :func:`asked_ahead`, before the :func:`drawn_by` block that
    waits for them (or draws them) with its own: the queue and the futures of those sent."""

    def __init__(self) -> None:
        self.queue: list[_Job] = []
        self.sent: dict[int, Any] | None = None


@contextmanager
def asked_ahead(workers: int) -> Iterator[FiguresAhead]:
    """Within this block the figure functions queue their figures as within
    :func:`drawn_by` and return their paths; at its end the figures are sent to the started
    drawing processes (if any), but nothing is waited for: a later ``drawn_by(workers,
    ahead=...)`` block does that (or draws those not sent) with its own figures. ``opspec
    evaluate --workers W`` asks so for the report's figures that need neither the sample
    index nor the summaries, as soon as the last replication is stored: they are drawn while
    the evaluate process builds the index and the summaries, when a core is idle otherwise.
    With one worker the figures are drawn as they are asked for (nothing is left to the
    later block).

    They are sent in ``workers - 1`` batches, each drawn by one process figure after figure,
    so that the evaluate process keeps a core of its own for the index: sent one by one to
    two processes on two cores, they took a third of its core, and the index took about
    twice as long."""
    ahead = FiguresAhead()
    if workers <= 1:
        yield ahead
        return
    token, sending = _QUEUE.set(ahead.queue), _SENT.set(None)
    try:
        yield ahead
    finally:
        _QUEUE.reset(token)
        _SENT.reset(sending)
    pools = started_pools()
    if pools is None or not ahead.queue:
        return                          # drawn with the drawn_by block's figures
    ahead.sent = {}
    batches: list[list[int]] = [list(range(len(ahead.queue)))[first::workers - 1]
                                for first in range(min(workers - 1, len(ahead.queue)))]
    for batch in batches:
        jobs = [_named(ahead.queue[index]) for index in batch]
        if any(job is None for job in jobs):
            continue                    # a replaced figure function: drawn by drawn_by
        try:
            future = pools.submit(_draw_all_named, jobs)
        except Exception:  # noqa: BLE001, S112 - a process gone: drawn at drawn_by's end
            continue
        ahead.sent.update(dict.fromkeys(batch, future))


@contextmanager
def drawn_by(workers: int, ahead: FiguresAhead | None = None) -> Iterator[None]:
    """Within this block, the figure functions return the path they will write at once and
    the figures are drawn at the block's end, by up to ``workers`` processes side by side
    (each figure is independent of the others; the same bytes as drawn one after another),
    those of an enclosing :func:`.drawing_pools.drawing_processes` when there is one. With
    one worker they are drawn as they are asked for (nothing queued). ``opspec evaluate
    --workers W`` draws its report's figures so: what runs after the replications runs on
    one core otherwise, and with two workers it was most of the wall time saved.

    ``ahead``: figures asked for before this block (:func:`asked_ahead`, with the same
    ``workers``), drawn (or, those sent, waited for) at its end with the block's own."""
    if workers <= 1:                # drawn as they are asked for, as without this block
        yield
        return
    queue: list[_Job] = ahead.queue if ahead is not None else []
    # with started drawing processes, each figure is sent to them as it is asked for: they
    # draw while this process still works out the report's other figures and tables
    sent: dict[int, Any] | None
    if ahead is not None and ahead.queue:
        sent = ahead.sent               # the processes that were there when they were sent
    else:
        sent = {} if started_pools() is not None else None
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
    pools = started_pools()
    draw, args, kwargs, fmt = queue[-1]
    name = getattr(draw, "__name__", "")
    if pools is None or _FIGURES.get(name) is not draw:
        return
    try:
        sent[len(queue) - 1] = pools.submit(_draw_named, name, args, kwargs, fmt)
    except Exception:  # noqa: BLE001, S110 - a process gone: drawn at the block's end
        pass


def _draw(queue: Sequence[_Job], workers: int, sent: Mapping[int, Any] | None = None
          ) -> None:
    global _JOBS
    sent = sent or {}
    if workers > 1 and (len(queue) > 1 or sent):
        pools = started_pools()
        if pools is not None and _on_started(pools, queue, sent):
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
    """Draw ``queue`` on the processes :func:`.drawing_pools.drawing_processes` started, the
    figure functions sent by name (they were forked before the figures were asked for); those
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


def _named(job: _Job) -> tuple[str, tuple[Any, ...], dict[str, Any], str | None] | None:
    """``job`` as a started drawing process is sent it (its function by name), or None
    when its function is not the one registered under its name."""
    draw, args, kwargs, fmt = job
    name = getattr(draw, "__name__", "")
    return (name, args, kwargs, fmt) if _FIGURES.get(name) is draw else None


def _draw_all_named(jobs: Sequence[tuple[str, tuple[Any, ...], dict[str, Any], str | None]]
                    ) -> None:
    for job in jobs:
        _draw_named(*job)


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


_Draw = Callable[..., Path]


def queueable(draw: _Draw) -> _Draw:
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
        queue.append((draw, args, kwargs, chosen_format()))
        sent = _SENT.get()
        if sent is not None:
            _send_now(queue, sent)
        path, fmt = written_as(signature.bind(*args, **kwargs).arguments["path"])
        return path.with_suffix(".svg") if fmt == "pdf" else path

    return figure

