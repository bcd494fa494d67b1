"""Building or walking a whole model at once without paying the cyclic garbage collector for it.

Loading a big specification creates hundreds of thousands of objects that all stay alive (the
tree, the model, the checks' indexes). Each of CPython's full collections walks every one of
them, and there are many while they are being created: for a 19 MB file with 50,000 AND
splits they took about 2 of validate's 9 seconds (benchmarks/parse_compile.py). Inside
:func:`gc_paused` the collector does not run; nothing else changes (objects that die are still
freed at once, by reference counting), and what cycles the block left behind are collected
at the collector's next full collection. opspec never uses ``gc.freeze`` otherwise.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["gc_paused"]


@contextmanager
def gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector for the block (re-entrant; it is enabled again on
    leaving the outermost block that found it enabled)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            # What the block made and kept joins the oldest generation at once (freezing and
            # unfreezing moves every tracked object there without looking at it): otherwise the
            # young generations' next collections would walk all of it once more.
            gc.freeze()
            gc.unfreeze()
            gc.enable()
