"""``opspec evaluate`` keeps what it loaded before its replications out of the collector's
full collections during the run (opspec.evaluation.memory.startup_frozen): the run's own
garbage is still freed when the run ends, what was there before is handed back to the
collector, and a process that froze objects of its own keeps them frozen."""

from __future__ import annotations

import gc
import weakref

from opspec.evaluation.memory import release_free_memory, startup_frozen


class _Node:
    def __init__(self) -> None:
        self.other: _Node | None = None


def _cycle() -> tuple[_Node, weakref.ref[_Node]]:
    node = _Node()
    node.other = node
    return node, weakref.ref(node)


def test_the_runs_garbage_is_freed_at_the_end_and_the_rest_handed_back() -> None:
    gc.collect()
    before, before_ref = _cycle()
    with startup_frozen():
        assert gc.get_freeze_count() > 0
        del before                              # garbage now, but frozen: left alone
        gc.collect()
        assert before_ref() is not None
        during, during_ref = _cycle()
        del during
    assert during_ref() is None                 # collected as the block ended
    assert gc.get_freeze_count() == 0
    release_free_memory()                       # a later full collection frees the rest
    assert before_ref() is None


def test_an_error_in_the_run_still_hands_everything_back() -> None:
    try:
        with startup_frozen():
            raise ValueError("the run failed")
    except ValueError:
        pass
    assert gc.get_freeze_count() == 0


def test_objects_the_process_froze_itself_stay_frozen() -> None:
    gc.collect()
    mine, mine_ref = _cycle()
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        with startup_frozen():
            pass
        assert gc.get_freeze_count() == frozen
        del mine
        gc.collect()
        assert mine_ref() is not None           # still the caller's frozen object
    finally:
        gc.unfreeze()
    gc.collect()
    assert mine_ref() is None
