"""What an evaluation leaves behind is given back when it ends (opspec.evaluation.memory):
objects in reference cycles nobody holds are freed, what is still used is untouched."""

from __future__ import annotations

import gc
import weakref

from opspec.evaluation.memory import release_free_memory


class _Node:
    def __init__(self) -> None:
        self.other: _Node | None = None


def test_unreachable_cycles_are_freed_and_what_is_held_is_kept():
    gc.collect()
    gc.disable()                # the collector must not run on its own in between
    try:
        lost, kept = _Node(), _Node()
        lost.other, kept.other = lost, kept          # two cycles
        gone = weakref.ref(lost)
        del lost
        assert gone() is not None                    # a cycle: refcounting cannot free it
        release_free_memory()
        assert gone() is None
        assert kept.other is kept
    finally:
        gc.enable()
