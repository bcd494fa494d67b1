"""`opspec evaluate --workers 2` forks one drawing process before it loads the spec (on the
core its start-up leaves idle); that one imports matplotlib and then forks the others, which
inherit its import (``plots.drawing_processes``). The figures those processes draw must be
the bytes drawn one after another, whichever process draws each; a process that cannot be
forked leaves its figures to the others (or to this process); and none outlives the block,
a failure within it, or a killed evaluate process."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from figure_samples import RATES, figures

from opspec.evaluation import drawing_pools, plots


def _figures(folder: Path) -> list[Path]:
    """The three sample figures and a fourth: a rates figure of one row."""
    return [*figures(folder), plots.rates_figure(RATES[:1], folder / "rates-1.svg")]


def _drawing_children() -> int:
    return len(multiprocessing.active_children())


def _who(pause: float = 0.0) -> tuple[int, int, bool]:
    """Run in a drawing process: its pid, its parent's, whether matplotlib is imported."""
    time.sleep(pause)
    return os.getpid(), os.getppid(), "matplotlib.figure" in sys.modules


def _both(pools: drawing_pools._Pools) -> list[tuple[int, int, bool]]:
    """What :func:`_who` says in each of the two processes: two jobs at once, each taken by
    a free process, until the second (forked once the first has imported matplotlib)
    takes one."""
    for _ in range(40):
        answers = [future.result() for future in [pools.submit(_who, 0.25)
                                                  for _ in range(2)]]
        if answers[0][0] != answers[1][0]:
            return answers
    raise AssertionError("one process took every job")


def _gone(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    return state in ("Z", "X")              # ended, not yet collected by whoever adopted it


def test_one_forked_here_the_other_by_it_and_the_same_figures(tmp_path: Path) -> None:
    alone = _figures(tmp_path / "alone")
    before = _drawing_children()
    with plots.drawing_processes(2):
        assert _drawing_children() == before + 1        # the second is not this one's child
        pools = drawing_pools.started_pools()
        assert pools is not None
        # both have matplotlib before drawing anything, the second forked by the first
        (first, parent, ready), (second, its_parent, its_ready) = sorted(
            _both(pools), key=lambda answer: answer[1] != os.getpid())
        assert parent == os.getpid() and its_parent == first
        assert ready and its_ready
        with plots.drawn_by(2):
            together = _figures(tmp_path / "together")
        assert all(p.is_file() for p in together)
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]
    assert _drawing_children() == before
    assert _gone(second)


def test_a_process_the_first_cannot_fork_leaves_its_figures_to_the_first(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = _figures(tmp_path / "alone")

    def refused() -> int:
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(drawing_pools, "_fork", refused)    # the first inherits it
    with plots.drawing_processes(2):
        pools = drawing_pools.started_pools()
        assert pools is not None
        pids = {future.result()[0] for future in [pools.submit(_who) for _ in range(4)]}
        with plots.drawn_by(2):
            together = _figures(tmp_path / "together")
    assert len(pids) == 1 and os.getpid() not in pids
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]


def test_a_first_process_that_cannot_be_forked_leaves_the_figures_to_this_process(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """When the machine refuses the fork (too many processes), every figure is drawn here,
    the same bytes."""
    alone = _figures(tmp_path / "alone")
    fork = multiprocessing.get_context("fork")

    class Refused(type(fork).Process):  # type: ignore[misc]
        def start(self) -> None:
            raise OSError(11, "Resource temporarily unavailable")

    class Refusing(type(fork)):  # type: ignore[misc]
        Process = Refused

    monkeypatch.setattr(multiprocessing, "get_context", lambda method=None: Refusing())
    before = _drawing_children()
    with plots.drawing_processes(2):
        assert drawing_pools.started_pools() is None and _drawing_children() == before
        with plots.drawn_by(2):
            here = _figures(tmp_path / "here")
    assert [p.read_bytes() for p in here] == [p.read_bytes() for p in alone]


def test_a_failure_ends_both_processes_at_once_while_they_draw(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # a process left to notice its parent gone by itself would live on for a minute
    monkeypatch.setattr(drawing_pools, "_WATCH_EVERY", 60.0)
    before = _drawing_children()
    started = time.monotonic()
    with pytest.raises(RuntimeError, match="a bad spec"), plots.drawing_processes(2):
        pools = drawing_pools.started_pools()
        assert pools is not None
        pids = [pid for pid, _, _ in _both(pools)]
        pools.submit(_who, 60)              # each busy for a minute
        pools.submit(_who, 60)
        time.sleep(0.2)
        raise RuntimeError("a bad spec")
    assert time.monotonic() - started < 20
    assert _drawing_children() == before
    deadline = time.monotonic() + 2
    while not all(_gone(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert all(_gone(pid) for pid in pids)


_KILLED = """
import os, sys, time
from opspec.evaluation import drawing_pools
from opspec.evaluation.drawing_pools import drawing_processes

def who():
    time.sleep(0.25)
    return os.getpid()

with drawing_processes(2):
    pools = drawing_pools.started_pools()
    for _ in range(40):
        pids = {future.result() for future in [pools.submit(who), pools.submit(who)]}
        if len(pids) == 2:
            break
    print(*pids, flush=True)
    time.sleep(120)
"""


@pytest.mark.skipif(not hasattr(os, "fork"), reason="the drawing processes are forked")
def test_no_drawing_process_outlives_a_killed_evaluate_process(tmp_path: Path) -> None:
    script = tmp_path / "killed.py"
    script.write_text(_KILLED, encoding="utf-8")
    with subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                          text=True) as evaluate:
        try:
            pids = [int(pid) for pid in evaluate.stdout.readline().split()]  # type: ignore[union-attr]
        finally:
            evaluate.send_signal(signal.SIGKILL)
    assert len(set(pids)) == 2
    deadline = time.monotonic() + 10
    while not all(_gone(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert all(_gone(pid) for pid in pids), "orphaned drawing processes"


def _die() -> None:
    """Run in a drawing process: it ends at once, as a killed or crashed one does."""
    os._exit(1)


def test_a_drawing_process_that_dies_leaves_no_pickle_to_the_collector() -> None:
    """A figure is sent to its drawing process as a pickle that is a view of a BytesIO. If
    that view outlived the sending (kept by the thread's frame, which the pipe's error caught
    in a reference cycle), the collector cleared the BytesIO while the view still held its
    buffer, and on Python 3.12 and later printed "Exception ignored in: <_io.BytesIO ...>
    BufferError: Existing exports of data" to the user's terminal (CPython gh-111331): seen
    on 3.13 after `evaluate --workers 2` runs that exported traces or hit a full disk. The
    garbage the drawing leaves must hold no such view, on every version."""
    import gc

    gc.collect()
    with plots.drawing_processes(2):
        pools = drawing_pools.started_pools()
        assert pools is not None
        with pytest.raises(Exception, match="drawing process ended"):
            pools.submit(_die).result(timeout=60)
    gc.set_debug(gc.DEBUG_SAVEALL)
    try:
        gc.collect()
        views = [o for o in gc.garbage if isinstance(o, memoryview)]
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
    assert views == []


def _opspec_threads() -> list[str]:
    import threading

    return [t.name for t in threading.enumerate() if t.name.startswith("opspec-drawing")]


def test_no_thread_of_this_process_or_the_first_is_there_when_they_fork(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # evaluate forks its replication workers inside this block, and the first drawing
    # process forks the others: a fork of a process with threads can leave a lock another
    # thread held locked in the child (Python 3.12+ warns "This process is multi-threaded,
    # use of fork() may lead to deadlocks in the child")
    counts = tmp_path / "threads-at-fork"

    def counting_fork() -> int:
        import threading

        with counts.open("a") as out:               # written by the first drawing process
            out.write(f"{threading.active_count()}\n")
        return os.fork()

    monkeypatch.setattr(drawing_pools, "_fork", counting_fork)
    with plots.drawing_processes(3):
        pools = drawing_pools.started_pools()
        assert pools is not None
        for _ in range(100):                        # until the first has forked the others
            if counts.is_file() and len(counts.read_text().split()) == 2:
                break
            time.sleep(0.05)
        assert _opspec_threads() == []              # here, before the first figure
        answers = {pools.submit(_who, 0.2).result()[0] for _ in range(6)}
        assert answers and len(_opspec_threads()) == 3     # handing the figures over now
    assert counts.read_text().split() == ["1", "1"]


def test_a_block_ended_before_any_figure_ends_its_processes_without_waiting(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # the threads that learn the forked processes' pids start only with the first figure:
    # a block that asks for none (a bad input, Ctrl-C during the replications) still ends
    # every process it started at once, not after the 5 s it would wait for a pid to be said
    pids = tmp_path / "forked"

    def recording_fork() -> int:
        pid = os.fork()
        if pid:
            pids.write_text(str(pid))
        return pid

    monkeypatch.setattr(drawing_pools, "_fork", recording_fork)
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt), plots.drawing_processes(2):
        for _ in range(100):                        # until the first has forked the second
            if pids.is_file() and pids.read_text():
                break
            time.sleep(0.05)
        raise KeyboardInterrupt
    assert time.monotonic() - started < 4.5         # (the stall this guards against: 5 s)
    assert _drawing_children() == 0
    assert _gone(int(pids.read_text()))


def test_a_block_ended_early_returns_only_once_its_processes_have_ended(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # a process forked by the first closes its files (its pipe, the first's sentinel, which
    # the block's wait for the first watches) a moment before it has ended: on a busy machine
    # CI once saw it still there after the block. Here that moment lasts half a second.
    pids = tmp_path / "forked"

    def slow_to_end(signum: int, frame: object) -> None:
        os.closerange(3, 4096)
        time.sleep(0.5)
        os._exit(1)

    def recording_fork() -> int:
        pid = os.fork()
        if pid:
            pids.write_text(str(pid))
        else:
            signal.signal(signal.SIGTERM, slow_to_end)
        return pid

    monkeypatch.setattr(drawing_pools, "_fork", recording_fork)
    with pytest.raises(KeyboardInterrupt), plots.drawing_processes(2):
        pools = drawing_pools.started_pools()
        assert pools is not None
        _both(pools)                                # both have started and said who they are
        raise KeyboardInterrupt
    assert _gone(int(pids.read_text()))
