"""Give back what an evaluation no longer uses, once it is over.

After ``opspec evaluate`` the process holds, beside what it still uses, two kinds of memory
that grow with the number of users although nothing reads them any more: objects in
reference cycles that Python's collector has not reached yet (it collects the oldest
generation only now and then), and memory the C allocator was given back but keeps in its
free lists instead of returning it to the system. Measured after `evaluate --days 1
--workers 1` (glibc's ``mallinfo2``, docs/engine-performance.md): the allocator's memory in
use was 21.2 MiB at 10,000 and at 100,000 users alike, while the resident size was 124 and
150 MiB; a full collection and ``malloc_trim`` brought both to 111 MiB.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import sys
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["release_free_memory", "startup_frozen"]


@contextmanager
def startup_frozen() -> Iterator[None]:
    """Within this block the collector leaves alone the objects that exist when it starts
    (``gc.freeze``): the modules, the spec and the user model an evaluation loads before
    its replications, about 80,000 objects, which every full collection during the run
    (the replications, the report's matplotlib) scanned again, and few of which become
    garbage. At the block's end the run's garbage is collected, still without them (what
    :func:`release_free_memory` needs to find, which grows with the users; a full
    collection scanned the 130,000 objects then alive), and they are handed back to the
    collector (``gc.unfreeze``): what became garbage among them, a fixed amount, goes at
    its next full collection. Forked workers inherit the frozen objects without touching
    them (no copy-on-write of their pages by the collector). A process that froze objects
    of its own is left as it is. Nothing a run computes depends on when the collector
    runs."""
    if gc.get_freeze_count():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.collect()
        gc.unfreeze()


def release_free_memory(*, collect: bool = True) -> None:
    """Collect every generation (unless ``collect`` is False: done already, as at the end of
    :func:`startup_frozen`), then ask glibc's allocator to return its free memory to the
    system (``malloc_trim(0)``; nothing to ask elsewhere). Frees nothing in use."""
    if collect:
        gc.collect()
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim = libc.malloc_trim
    except (OSError, AttributeError):  # musl and others: no malloc_trim, nothing to do
        return
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    trim(0)
