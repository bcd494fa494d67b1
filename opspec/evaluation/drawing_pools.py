"""The drawing processes: worker processes started before the report's figures are asked
for, which import matplotlib (and load its font) while the evaluate process still loads the
spec or runs its replications, and then draw the figures :mod:`.figure_queue` sends them.
``opspec evaluate --workers W`` starts them (:func:`drawing_processes`).

One process is forked at once; it imports matplotlib and then forks the others itself, so
that they inherit its import instead of each paying for it again (0.27 CPU-s a process,
during the replications, which ``--workers 1`` does not pay). The figures wait in one queue
of the evaluate process; a thread of it per drawing process (:class:`_Drawer`) hands the
next one (a module-level function, pickled by name, and its arguments) to its process over
a pipe of their own as soon as that process is free, so each figure goes to the first
process free to draw it.

No process forks while it has a thread of its own (a lock another thread held would stay
held in the child; Python 3.12+ warns of it): the evaluate process starts those threads
with the first figure, after it has forked its replication workers, and the first drawing
process starts watching its parent only once it has forked the others.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

from opspec.evaluation.matplotlib_import import import_matplotlib as _import_matplotlib

__all__ = ["drawing_processes", "started_pools"]


@contextmanager
def drawing_processes(workers: int) -> Iterator[None]:
    """Start up to ``workers`` drawing processes now, for the :func:`.figure_queue.drawn_by`
    blocks within this one. ``opspec evaluate --workers W`` starts them before it loads the
    spec: the first one imports matplotlib (and loads its font) on the core that start-up
    leaves idle, then forks the others, which inherit its import; matplotlib is ready when
    the first figure is asked for. Nothing happens with one worker or where processes cannot
    be forked.

    A failure or Ctrl-C within the block ends the processes at once, without waiting for
    their import."""
    if workers <= 1 or not hasattr(os, "fork") or _POOL.get() is not None:
        yield
        return
    import multiprocessing

    pools = _Pools(multiprocessing.get_context("fork"), os.getpid(), workers)
    try:
        pools.start()                       # forks the first now (not at the first figure)
    except Exception:  # noqa: BLE001 - no processes: the figures are drawn as before
        pools.end_now()                     # what was started before the failure, if any
        yield
        return
    token = _POOL.set(pools)
    try:
        yield
    except BaseException:
        # the command failed or was stopped (a bad spec, Ctrl-C): nothing more to draw, and
        # a process still importing matplotlib is not waited for (the error is shown now)
        pools.end_now()
        raise
    finally:
        _POOL.reset(token)
        pools.shutdown()


def started_pools() -> _Pools | None:
    """The drawing processes of the :func:`drawing_processes` block this is called in, if
    they were started."""
    return _POOL.get()


#: A figure to draw: its future, and the function (module-level, pickled by name) and its
#: arguments; ``None`` tells a drawing process to end.
_Job = tuple[Any, Callable[..., Any], tuple[Any, ...]]


class _Drawer:
    """One drawing process as the evaluate process sees it: its pipe, the thread that hands
    it the jobs waiting in the pools' queue one at a time (whichever process is free takes
    the next figure; a job waits there, not in a pipe, so that a large one never blocks the
    evaluate process while the drawing processes are busy), and its process id (the first's
    known at its fork; the others say theirs as they start, and are then held by a pidfd,
    which stays that process's whatever becomes of its pid)."""

    def __init__(self, end: Any, pid: int | None, pools: _Pools) -> None:
        self.end, self.pid, self._pools = end, pid, pools
        self.pidfd: int | None = None
        self.gone = False                   # takes no more jobs: told to end, or gone
        self.known = threading.Event()      # its pid is known, or it is gone
        self.thread = threading.Thread(target=self._hand_over, name="opspec-drawing",
                                       daemon=True)

    def _hand_over(self) -> None:
        from multiprocessing.reduction import ForkingPickler

        job: _Job | None = None
        ended: BaseException | None = None
        try:
            if self.pid is None:
                self.pid = self.end.recv()  # a process forked by the first says who it is
                self.pidfd = _pidfd(self.pid)
            self.known.set()
            while True:
                job = self._pools.jobs.get()
                if job is None:             # the block ended: the process may end
                    with contextlib.suppress(OSError):
                        self.end.send(None)
                    return
                future, fn, args = job
                if not future.set_running_or_notify_cancel():
                    continue
                try:
                    message = ForkingPickler.dumps((fn, args))
                except Exception as error:  # noqa: BLE001 - what cannot be sent fails alone
                    future.set_exception(error)
                    continue
                try:
                    self.end.send_bytes(message)
                finally:
                    # the pickle is a view of a BytesIO: let it go now. Kept to the end of
                    # this thread and caught in a reference cycle (the error below), it made
                    # the collector print "Exception ignored in: <_io.BytesIO ...>
                    # BufferError" to the user's terminal (CPython gh-111331)
                    message.release()
                try:
                    done, value = self.end.recv()
                except (EOFError, OSError):
                    raise
                except Exception as error:  # noqa: BLE001 - an answer that cannot be read
                    done, value = False, error
                (future.set_result if done else future.set_exception)(value)
                job = None
        except Exception as error:  # noqa: BLE001 - the pipe shut: the process is gone
            ended = error.with_traceback(None)  # no cycle through this frame
        finally:
            self.known.set()
            self._pools.ended(self, job, ended)


class _Pools:
    """The drawing processes of :func:`drawing_processes` as one executor: the first forked
    by :meth:`start`, the others forked by the first once its matplotlib is imported; each
    figure goes to the first process free to draw it."""

    def __init__(self, context: Any, parent: int, workers: int) -> None:
        import queue

        self._context, self._parent, self._workers = context, parent, workers
        self._first: Any = None
        self._drawers: list[_Drawer] = []
        self.jobs: queue.SimpleQueue[_Job | None] = queue.SimpleQueue()
        # held while a job is queued or a drawer's end is noted: no job is queued once
        # every drawer has stopped taking them
        self._lock = threading.Lock()

    def start(self) -> None:
        ends: list[tuple[Any, Any]] = []
        try:
            ends.extend(self._context.Pipe() for _ in range(self._workers))
            self._first = self._context.Process(
                target=_first_process, name="opspec-drawing",
                args=(self._parent, [theirs for _, theirs in ends],
                      [ours for ours, _ in ends]))
            self._first.start()
        except BaseException:
            for ours, _ in ends:
                ours.close()
            raise
        finally:
            for _, theirs in ends:          # theirs alone: a gone process is an end of file
                theirs.close()
        self._drawers = [_Drawer(ours, self._first.pid if i == 0 else None, self)
                         for i, (ours, _) in enumerate(ends)]

    def _start_threads(self) -> None:
        """The threads that hand the jobs over, started at the first job (or at the end):
        not at the start, so that the evaluate process has no thread of its own when it
        forks its replication workers (a fork of a process with threads is what Python 3.12+
        warns of: a lock another thread held stays held in the child)."""
        with self._lock:
            for drawer in self._drawers:
                if drawer.thread.ident is None:
                    drawer.thread.start()

    def submit(self, fn: Callable[..., Any], /, *args: Any) -> Any:
        import concurrent.futures as cf
        from concurrent.futures.process import BrokenProcessPool

        future: cf.Future[Any] = cf.Future()
        self._start_threads()
        with self._lock:
            if all(drawer.gone for drawer in self._drawers):
                raise BrokenProcessPool("the drawing processes ended")
            self.jobs.put((future, fn, args))
        return future

    def ended(self, drawer: _Drawer, job: _Job | None, error: BaseException | None
              ) -> None:
        """``drawer`` takes no more jobs (it was told to end, or its process is gone): the
        job it had fails (the figures are then drawn by the evaluate process, where an error
        is plain); once no drawer is left, so do those still queued."""
        from concurrent.futures.process import BrokenProcessPool

        broken = BrokenProcessPool(f"a drawing process ended ({type(error).__name__})")
        with self._lock:
            drawer.gone = True
            left = [] if not all(d.gone for d in self._drawers) else [
                self.jobs.get() for _ in range(self.jobs.qsize())]
        for item in [job, *left]:
            if item is not None and not item[0].done():
                with contextlib.suppress(Exception):
                    item[0].set_exception(broken)

    def shutdown(self) -> None:
        """Let the processes end once they have drawn what was sent, and wait for them."""
        self._start_threads()
        for _ in self._drawers:
            self.jobs.put(None)
        for drawer in self._drawers:
            drawer.thread.join()
        if self._first is not None:
            self._first.join()              # which waits for the processes it forked
        self._close_pidfds(wait=5.0)        # (reaped by the first: no wait)

    def end_now(self) -> None:
        """End every drawing process without waiting for its work, and then the threads
        that sent them jobs."""
        import signal

        ended: set[int] = set()
        self._start_threads()               # each thread learns its process's pid, or EOF

        def end(drawer: _Drawer) -> None:
            # a process forked by the first: ended once its pid is known, and only while
            # its pipe is open (a pid of a process gone may be another's by now)
            if drawer.known.is_set() and not drawer.gone and drawer.pid not in (None, *ended):
                ended.add(drawer.pid)
                with contextlib.suppress(OSError):
                    if drawer.pidfd is not None:
                        signal.pidfd_send_signal(drawer.pidfd, signal.SIGTERM)
                    else:
                        os.kill(drawer.pid, signal.SIGTERM)

        for drawer in self._drawers[1:]:
            end(drawer)
        first = self._first
        if first is not None:
            with contextlib.suppress(Exception):
                first.terminate()
            with contextlib.suppress(Exception):
                first.join(5)
                if first.is_alive():
                    first.kill()
                    first.join(5)
        # the first is gone: a process it forked has said who it is, or is gone too (its
        # end of the pipe closed); one forked as the first was ended is ended now
        for drawer in self._drawers[1:]:
            drawer.known.wait(5)
            end(drawer)
        for _ in self._drawers:
            self.jobs.put(None)             # a thread waiting for a job finds the pipe shut
        for drawer in self._drawers:
            drawer.thread.join(5)
        # a signal is only a request, and the first's end (which join waits for) is seen
        # once the processes it forked have closed their files, a moment before they have
        # ended: on a busy machine one was still there after the block (CI saw it)
        self._close_pidfds(wait=5.0)

    def _close_pidfds(self, wait: float) -> None:
        """Wait up to ``wait`` seconds for the processes forked by the first to have ended
        (each pidfd turns readable then; they are not this process's children, so it cannot
        wait for them as such), and let the pidfds go."""
        import select
        import time

        pidfds = [drawer.pidfd for drawer in self._drawers if drawer.pidfd is not None]
        deadline = time.monotonic() + wait
        for pidfd in pidfds:
            with contextlib.suppress(OSError, ValueError):
                select.select([pidfd], [], [], max(0.0, deadline - time.monotonic()))
            with contextlib.suppress(OSError):
                os.close(pidfd)
        for drawer in self._drawers:
            drawer.pidfd = None


#: Within :func:`drawing_processes`: its processes (:class:`_Pools`).
_POOL: ContextVar[_Pools | None] = ContextVar("opspec_drawing_pool", default=None)


def _first_process(parent: int, ends: list[Any], not_ours: list[Any]) -> None:
    """The first drawing process: matplotlib imported, the others forked (each inherits the
    import), its own jobs drawn; it ends once the processes it forked have ended."""
    for end in not_ours:                    # the evaluate process's ends of the pipes
        end.close()
    _leave_ctrl_c()
    _warm_up()
    forked = []
    for end in ends[1:]:
        try:
            forked.append(_fork_sibling(end, ends))
        except OSError:                     # the first draws what that one would have
            pass
        end.close()                         # that process's alone now (or nobody's)
    # watched from now on, not during the import: a thread of its own would be in the
    # process it forks above (which Python 3.12+ warns of); a parent gone meanwhile is seen
    # at the watch's first look
    _watch(parent)
    try:
        _serve(ends[0])
    finally:
        for pid in forked:                  # their CPU time counts as this process's
            with contextlib.suppress(OSError):
                os.waitpid(pid, 0)


def _fork_sibling(end: Any, ends: list[Any]) -> int:
    """Fork a drawing process from the first, which has imported matplotlib: it draws the
    jobs sent on ``end``. Returns its pid (in the first process)."""
    import sys

    first = os.getpid()
    for stream in (sys.stdout, sys.stderr):     # nothing buffered is written twice
        with contextlib.suppress(Exception):
            stream.flush()
    pid = _fork()
    if pid:
        return pid
    status = 1
    try:
        for other in ends:
            if other is not end:
                other.close()
        _leave_ctrl_c()
        end.send(os.getpid())               # said before the watch can end this process:
        _watch(first)                       # the evaluate process then waits for its end
        _serve(end)
        status = 0
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(status)


def _pidfd(pid: int) -> int | None:
    """A pidfd of process ``pid`` (Linux 5.3 and later), or None where there is none or the
    process is gone."""
    try:
        return os.pidfd_open(pid)
    except (AttributeError, OSError):
        return None


#: How the first drawing process forks the others (a test refuses it).
_fork = os.fork if hasattr(os, "fork") else None


#: Seconds between two looks of a drawing process at its parent.
_WATCH_EVERY = 1.0


def _leave_ctrl_c() -> None:
    """Ctrl-C left to the evaluate process (which ends the drawing; no traceback from each
    drawing process)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _watch(parent: int) -> None:
    """An end of this process's own when its parent is gone (killed: it cannot end it, and
    a drawing process waiting for figures would live on)."""
    import time

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(_WATCH_EVERY)
        os._exit(1)

    threading.Thread(target=watch, name="opspec-drawing-watch", daemon=True).start()


def _warm_up() -> None:
    """matplotlib imported, its default font found and loaded, and what the figure
    functions import as they draw (the numbers' format, the panels' layout: 0.02 CPU-s,
    which each process otherwise paid after the replications)."""
    try:
        _import_matplotlib()
        from matplotlib import font_manager
        from matplotlib.ft2font import FT2Font

        FT2Font(font_manager.findfont(font_manager.FontProperties()))
        import opspec.evaluation.figure_layout
        import opspec.evaluation.tables  # noqa: F401
    except Exception:  # noqa: BLE001, S110 - a figure drawn later says what is wrong
        pass


def _serve(end: Any) -> None:
    """Run the jobs sent on ``end`` one after another, answering each with whether it
    returned and its value or error, until told to stop or the pipe is shut."""
    import pickle

    while True:
        try:
            message = end.recv_bytes()
        except EOFError:
            return
        try:
            job = pickle.loads(message)     # from the evaluate process
            if job is None:
                return
            fn, args = job
            reply: tuple[bool, Any] = (True, fn(*args))
        except Exception as error:  # noqa: BLE001 - the evaluate process decides
            reply = (False, error)
        try:
            end.send(reply)
        except Exception as error:  # noqa: BLE001 - an answer that cannot be pickled
            end.send((False, RuntimeError(f"{type(error).__name__}: {error}")))
