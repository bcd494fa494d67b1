"""The drawing processes: worker processes started before the report's figures are asked
for, which import matplotlib (and load its font) while the evaluate process still runs its
replications or works out what to draw, and then draw the figures :mod:`.figure_queue` sends
them. ``opspec evaluate --workers W`` starts them (:func:`drawing_processes`, within
:func:`staggered_start`).

The functions they are sent (:func:`_warm_up`, :func:`_ready`, and the queue's
``_draw_named``) are module-level functions, pickled by name.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

from opspec.evaluation.matplotlib_import import import_matplotlib as _import_matplotlib

__all__ = ["drawing_processes", "staggered_start", "started_pools", "warm_up_the_rest"]


@contextmanager
def drawing_processes(workers: int) -> Iterator[None]:
    """Start up to ``workers`` drawing processes now, for the :func:`.figure_queue.drawn_by`
    blocks within this one: each imports matplotlib (and loads its font) while this process
    still works out what to draw. ``opspec evaluate --workers W`` starts them before its
    replications, so that matplotlib is ready when the first figure is asked for: its
    import (0.3 CPU-s in each process) shares the cores with the replications' chunks, which
    any core can run, instead of delaying the figures after them. Nothing happens with one
    worker or where processes cannot be forked.

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
            except Exception:  # noqa: BLE001 - the first ones draw every figure
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



def started_pools() -> _Pools | None:
    """The drawing processes of the :func:`drawing_processes` block this is called in, if
    they were started."""
    started = _POOL.get()
    return None if started is None else started[0]
