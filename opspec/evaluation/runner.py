"""Run an evaluation's replications on ``concurrent.futures`` executors and store each result.

- one worker: replications run in this process (no pool to start);
- ``workers > 1``: a process pool of that many workers;
- ``scheduler``: an existing Dask distributed cluster, through ``client.get_executor()`` —
  the same code path as the pool.
Users are sent in chunks so the per-task overhead stays negligible; every record is stored
(and committed) in this process as soon as its chunk and the chunks sent before it have
returned: in the order sent, so that the store's rows (and the trace exports) are those of
one worker whatever the number of workers. A chunk whose worker dies is recorded as failed
replications with the reason; ``--resume`` runs them again.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import BrokenExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from opspec.errors import EvaluationError
from opspec.evaluation.plan import EvaluationPlan
from opspec.evaluation.replication import ReplicationRecord, run_users
from opspec.evaluation.store import ResultStore

__all__ = ["EvaluationOutcome", "Progress", "check_scheduler", "chunks", "iter_chunks",
           "run_evaluation"]


@dataclass(frozen=True, slots=True)
class EvaluationOutcome:
    """How the run went: replications done now, already stored, failed, and wall time."""

    done: int
    skipped: int
    failed: int
    wall_s: float


class Progress:
    """Receives progress; the CLI shows a bar or log lines. ``total`` is set once."""

    def start(self, total: int, already: int) -> None: ...

    def advance(self, n: int) -> None: ...

    def finish(self) -> None: ...


TraceSink = Callable[[ReplicationRecord], None]

# Seconds to wait for a Dask scheduler to answer.
SCHEDULER_TIMEOUT = 10

#: Default seconds to wait for a Dask cluster to have a worker: at the start, and whenever every
#: worker has left during the run (``--scheduler-timeout``). A cluster without workers accepts
#: tasks and never runs them: without this wait the run would hang.
WORKER_TIMEOUT = 60.0

# Seconds between two looks at the cluster while no chunk finishes.
_POLL = 1.0

# Users per chunk when traces are exported (each chunk's traces cross to the parent at once).
EXPORT_CHUNK = 4


def chunks(users: Sequence[int], workers: int, most: int = 50) -> list[list[int]]:
    """Chunks of about 8 per worker, 1 to ``most`` users each, in user order.

    With several workers the last chunks shrink (each about the users left over four per
    worker, down to an eighth of the full size), so the workers run out of work together:
    with equal chunks, one worker was left running the last chunk of 50 users (about 0.5 s
    of a user-month each) while the other core stood idle. Which users go together changes
    nothing in the results (each user's streams are their own)."""
    return list(iter_chunks(users, workers, most))


def iter_chunks(users: Sequence[int], workers: int, most: int = 50) -> Iterator[list[int]]:
    """:func:`chunks` one at a time, as they are sent: with ``users`` a ``range`` (a fresh
    run), the run never holds a list of every user (100,000 users were 4 MiB of int objects
    and lists in the evaluate process, the whole run long)."""
    if not users:
        return
    size = max(1, min(most, math.ceil(len(users) / (workers * 8))))
    if workers <= 1:
        for i in range(0, len(users), size):
            yield list(users[i:i + size])
        return
    least = max(1, size // 8)
    start = 0
    while start < len(users):
        step = max(least, min(size, math.ceil((len(users) - start) / (4 * workers))))
        yield list(users[start:start + step])
        start += step


def _connect(scheduler: str) -> Any:
    """A Dask client of the cluster at ``scheduler``, or a clear EvaluationError."""
    try:
        from distributed import Client
    except ImportError:
        raise EvaluationError("--scheduler needs dask.distributed",
                              hint="pip install 'opspec[dask]'") from None
    try:
        return Client(scheduler, timeout=SCHEDULER_TIMEOUT)  # type: ignore[no-untyped-call]
    except Exception as error:  # noqa: BLE001 - any connection failure, said plainly
        raise EvaluationError(f"cannot reach the Dask scheduler at {scheduler}: {error}",
                              hint="check the address (tcp://host:8786) and that the "
                              "scheduler is running") from None


def _no_workers(scheduler: str, timeout: float, during: str) -> EvaluationError:
    return EvaluationError(
        f"the Dask cluster at {scheduler} has no workers: none {during} in {timeout:g} s",
        hint=f"start workers (`dask worker {scheduler}`), or wait longer with "
        "--scheduler-timeout SECONDS")


def _wait_for_workers(client: Any, scheduler: str, timeout: float) -> None:
    """Return once the cluster has a worker; an EvaluationError after ``timeout`` seconds."""
    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        raise _no_workers(scheduler, timeout, "joined") from None
    except Exception as error:  # noqa: BLE001 - a lost scheduler, said plainly
        if "timed out" in str(error).lower() or "timeout" in type(error).__name__.lower():
            raise _no_workers(scheduler, timeout, "joined") from None
        raise EvaluationError(f"lost the Dask scheduler at {scheduler}: {error}") from None


def check_scheduler(scheduler: str, timeout: float = WORKER_TIMEOUT) -> None:
    """Connect to the Dask scheduler and wait until it has a worker (at most ``timeout``
    seconds), then disconnect: called before anything is created, so a wrong address or a
    cluster without workers fails without leaving an empty output folder behind."""
    client = _connect(scheduler)
    try:
        _wait_for_workers(client, scheduler, timeout)
    finally:
        client.close()


class _ClusterWatch:
    """Called while no chunk finishes: raises once the cluster has had no worker for
    ``timeout`` seconds (its workers were stopped or died; Dask would wait forever)."""

    def __init__(self, client: Any, scheduler: str, timeout: float) -> None:
        self.client, self.scheduler, self.timeout = client, scheduler, timeout
        self._empty_since: float | None = None

    def __call__(self) -> None:
        try:
            workers = len(self.client.nthreads())
        except Exception as error:  # noqa: BLE001 - a lost scheduler, said plainly
            raise EvaluationError(f"lost the Dask scheduler at {self.scheduler}: "
                                  f"{error}") from None
        now = time.monotonic()
        if workers:
            self._empty_since = None
        elif self._empty_since is None:
            self._empty_since = now
        elif now - self._empty_since >= self.timeout:
            raise _no_workers(self.scheduler, self.timeout, "came back")


Watch = Callable[[], None]


@contextmanager
def _executor(workers: int, scheduler: str | None, timeout: float = WORKER_TIMEOUT
              ) -> Iterator[tuple[cf.Executor | None, int, Watch | None]]:
    """The executor to use, how many chunks to keep in flight on it (None: in-process), and
    what to call while nothing finishes."""
    if scheduler:
        client = _connect(scheduler)
        try:
            _wait_for_workers(client, scheduler, timeout)
            threads = sum(client.nthreads().values())
            executor = client.get_executor()
            yield executor, max(2, 2 * threads), _ClusterWatch(client, scheduler, timeout)
        finally:
            client.close()
        return
    if workers <= 1:
        yield None, 1, None
        return
    import multiprocessing

    # fork keeps start-up cheap; each worker loads the spec once (replication.prepare)
    context = multiprocessing.get_context("fork" if hasattr(os, "fork")
                                          else "spawn")
    pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                  initializer=_exit_with_parent, initargs=(os.getpid(),))
    try:
        yield pool, 2 * workers, None
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _exit_with_parent(parent: int) -> None:
    """Pool worker initializer: end this worker when the evaluation process is gone.

    A killed evaluation (``kill -9``, out of memory) cannot shut its pool down, and workers
    blocked on their task queue would otherwise live on as orphans, holding CPU and memory.
    """
    import threading

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="opspec-parent-watch", daemon=True).start()


Chunk = tuple[str, list[int]]
Keep = Callable[[list[ReplicationRecord]], None]


def _drain(executor: cf.Executor, doc: dict[str, object], pending: Iterable[Chunk],
           slots: int, keep: Keep, watch: Watch | None = None,
           meanwhile: Callable[[], Any] | None = None) -> list[tuple[str, list[int], str]]:
    """Run ``pending`` chunks on ``executor``, at most ``slots`` in flight, storing each chunk
    as it returns. Returns the chunks lost because the process pool broke (a worker process
    died), with the reason; a chunk whose task raised becomes failed replications.

    Keeping only a few chunks in flight bounds the memory of results waiting to be stored
    (traces, when exporting) whatever the number of users. ``watch`` is called about once a
    second while no chunk finishes (and may raise: a cluster left without workers).
    ``meanwhile`` is called once the first chunks are sent (see :func:`_while_workers_start`).
    """
    queue = iter(pending)
    # each chunk's place in the order it was sent: chunks are stored in that order (those
    # back early wait for the ones before them), so the store's rows, the trace exports and
    # what is drawn from them are those of one worker whatever the number of workers
    running: dict[cf.Future[list[ReplicationRecord]], tuple[int, Chunk]] = {}
    back: dict[int, list[ReplicationRecord] | None] = {}   # None: lost, stored later
    sent = stored = 0
    lost: list[tuple[str, list[int], str]] = []

    def fill() -> None:
        nonlocal sent
        # at most ``slots`` chunks back early wait for a slow one: a bounded memory
        while len(running) < slots and len(back) < slots:
            item = next(queue, None)
            if item is None:
                return
            try:
                running[executor.submit(run_users, doc, *item)] = (sent, item)
                sent += 1
            except BrokenExecutor as error:
                reason = _dead_worker(error)
                lost.append((*item, reason))
                lost.extend((label, users, reason) for label, users in queue)
                return

    fill()
    _while_workers_start(meanwhile)
    while running:
        finished, _ = cf.wait(running, timeout=_POLL if watch is not None else None,
                              return_when=cf.FIRST_COMPLETED)
        if not finished and watch is not None:
            watch()
        for future in finished:
            place, (label, users) = running.pop(future)
            try:
                back[place] = future.result()
            except BrokenExecutor as error:
                lost.append((label, users, _dead_worker(error)))
                back[place] = None
            except Exception as error:  # noqa: BLE001 - a failed task, recorded
                back[place] = _failed(label, users, error)
        while stored in back:
            records = back.pop(stored)
            stored += 1
            if records is not None:
                keep(records)
            del records
        fill()
    return lost


def _while_workers_start(meanwhile: Callable[[], Any] | None = None) -> None:
    """What this process would do after the replications, done now that the workers have
    their first chunks: the summaries' interval functions load scipy.special (about 0.1
    CPU-s), and ``meanwhile`` (``opspec evaluate``: the report's modules and template),
    which otherwise ran after the last chunk while the workers' cores stood idle. The
    workers were forked before it, so they do not pay for it; the numbers are the same
    whenever it is loaded."""
    try:
        from opspec.statistics.intervals import t_quantile

        t_quantile(0.95, 1)
        if meanwhile is not None:
            meanwhile()
    except Exception:  # noqa: BLE001, S110 - the summaries load it again, and say why
        pass


def _failed(label: str, users: Sequence[int], error: Exception) -> list[ReplicationRecord]:
    """A chunk whose task raised: each of its users a failed replication with the reason."""
    reason = f"worker failed: {type(error).__name__}: {error}"
    return [ReplicationRecord(label, u, "failed", error=reason) for u in users]


def _dead_worker(error: BaseException) -> str:
    return f"worker failed: a worker process died ({type(error).__name__}: {error})"


def run_evaluation(plan: EvaluationPlan, store: ResultStore, *, workers: int = 1,
                   scheduler: str | None = None, progress: Progress | None = None,
                   on_trace: TraceSink | None = None, retrace: bool = False,
                   scheduler_timeout: float = WORKER_TIMEOUT,
                   on_stored: Callable[[], Any] | None = None,
                   meanwhile: Callable[[], Any] | None = None) -> EvaluationOutcome:
    """Run every replication of ``plan`` not yet stored as done, storing each as it ends.

    ``retrace`` (resuming a run that exports traces): the users already stored are simulated
    again, only for their traces — the same seed gives the same trace — so that the trace
    files of the resumed run hold every user, not just the ones run after the interruption.

    A worker process that dies (killed, out of memory) breaks its process pool and every chunk
    in flight with it: those chunks run once more in a fresh pool, and what fails again is
    stored as failed replications with the reason (``--resume`` runs them again).

    On a Dask cluster (``scheduler``), a cluster that has no worker for ``scheduler_timeout``
    seconds (at the start, or once all have left) stops the run with an EvaluationError;
    what finished is stored.

    ``on_stored`` is called once every replication is stored, as the sample index is begun
    (:meth:`ResultStore.index`; with W > 1 it is built beside): ``opspec evaluate --workers
    W`` asks then for the report's figures that do not read it, drawn beside the index.

    ``meanwhile`` is called once the worker processes have their first chunks (never when
    the replications run in this process): what the caller needs after the replications,
    loaded while this process mostly waits for them. What it raises is ignored (the
    caller meets it again where it is needed).
    """
    started = time.perf_counter()
    progress = progress or Progress()
    # the chunks are made as they are sent (pending is lazy), each from the users still to
    # run: a range when none is stored yet, so a fresh run holds no list of every user
    sources: list[tuple[str, Sequence[int], int]] = []
    skipped = 0
    # a user-month of the dispenser is ~0.4 MB of trace: small chunks when traces travel back
    most = EXPORT_CHUNK if plan.export else 50
    stored: set[tuple[str, int]] = set()
    not_retraced = 0
    for design in plan.designs:
        finished = store.finished(design.label)
        skipped += len(finished)
        stored.update((design.label, u) for u in finished)
        todo: Sequence[int] = (range(plan.users) if retrace or not finished
                               else [u for u in range(plan.users) if u not in finished])
        sources.append((design.label, todo, most))
    if plan.input_uncertainty:      # the parameter draws' users (never traced)
        from opspec.evaluation.input_uncertainty import draw_users, draws_label

        for design in plan.designs:
            label = draws_label(design.label)
            finished = store.finished(label)
            skipped += len(finished)
            not_retraced += len(finished)
            sources.append((label, [u for u in draw_users(plan) if u not in finished], 50))
    pending: Iterator[Chunk] = ((label, chunk) for label, todo, size in sources
                                for chunk in iter_chunks(todo, max(1, workers), most=size))
    total = (plan.users + plan.input_uncertainty * plan.users_per_draw) * len(plan.designs)
    progress.start(total, not_retraced if retrace else skipped)
    doc = plan.to_json()
    done = failed = 0

    def keep(records: list[ReplicationRecord]) -> None:
        nonlocal done, failed
        new: list[ReplicationRecord] = []
        for record in records:
            if on_trace is not None and record.trace is not None:
                on_trace(record)
            record.trace = None
            if (record.design, record.user) in stored:
                continue            # re-run for its trace only: the stored result stands
            new.append(record)
        store.add_many(new)         # the chunk in one transaction (see store.py)
        for record in new:
            if record.status == "done":
                done += 1
            else:
                failed += 1
        progress.advance(len(records))

    try:
        lost: list[tuple[str, list[int], str]] = []
        with _executor(workers, scheduler, scheduler_timeout) as (executor, slots, watch):
            if executor is None:
                for label, users in pending:
                    try:
                        records = run_users(doc, label, users)
                    except Exception as error:  # noqa: BLE001 - as a failed task in a pool
                        records = _failed(label, users, error)
                    keep(records)
            else:
                lost = _drain(executor, doc, pending, slots, keep, watch, meanwhile)
        if lost and scheduler is None:
            # one more try in a fresh pool (Dask reschedules lost tasks by itself)
            with _executor(workers, None) as (executor, slots, _):
                assert executor is not None
                lost = _drain(executor, doc, [(label, users) for label, users, _ in lost],
                              slots, keep)
        for label, users, reason in lost:
            keep([ReplicationRecord(label, u, "failed", error=reason) for u in users])
        # once, now that every replication is stored; with workers (W > 1) on a thread of
        # its own, beside what this process does next (the figures asked for ahead, the
        # summaries): what reads the samples waits for it
        store.index(beside=workers > 1)
        if on_stored is not None:
            on_stored()
    finally:
        progress.finish()
    return EvaluationOutcome(done, skipped, failed, time.perf_counter() - started)
