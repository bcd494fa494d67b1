"""Run state: workflow instances, frames (a token scope over a graph) and activity instances.

Plain ``__slots__`` objects keyed by small ints: the interpreter creates several per dose
cycle, so they stay small and cheap. Life-cycle states are ints from
:mod:`opspec.engine.lifecycle`.
"""

from __future__ import annotations

import types
from collections import ChainMap
from collections.abc import Callable, Mapping, MutableMapping
from typing import TYPE_CHECKING, Any, Final

from opspec.engine.lifecycle import NOT_STARTED

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledActivity, CompiledGraph, CompiledProcess
    from opspec.engine.performers import WorkItem

__all__ = ["ACTIVITY_FIELDS", "FRAME_FIELDS", "IN_LINE", "PROCESS_FIELDS", "ActivityInstance",
           "Frame", "MultiInstance", "ProcessInstance", "process_instance"]

# From source, the plans (opspec.engine.plans) make these objects in line: ``object.__new__``
# and the fields stored one by one, not a class call, which from source runs ``__init__``
# in a C-level call of its own (about 150 ns of an object's 250-300, and the dispenser's
# plans make about 15 a dose cycle). Each class's fields, in its ``__init__``'s order: a
# name alone is the constructor's parameter of that name; a pair, a field ``__init__`` is
# not given and the Python literal it starts at (tests/engine/test_made_in_line.py holds
# each table to its ``__init__``).
ACTIVITY_FIELDS: Final[tuple[str | tuple[str, str], ...]] = (
    "key", "act", "frame", "state", "started_at", ("item", "None"), ("child", "None"),
    ("iteration", "0"), ("gen", "0"), ("waiting", '""'), ("choice", "()"),
    ("cleanup", "None"), ("performer", "None"), ("mi", "None"), ("local", "None"))
PROCESS_FIELDS: Final[tuple[str | tuple[str, str], ...]] = (
    "id", "process", "data", "scope", "state", "priority", "parent", "root", ("frames", "[]"),
    "started_at", ("deferred", "None"), "trigger", ("depth", "0"), ("partner", "None"),
    ("view", "None"))
FRAME_FIELDS: Final[tuple[str | tuple[str, str], ...]] = (
    "graph", "inst", "owner", ("live", "0"), ("parked", "0"), ("joins", "None"),
    ("ors", "None"), ("running", "{}"), ("cjoins", "None"), ("owed", "None"),
    ("queue", "None"))


class ProcessInstance:
    """One running (or finished) workflow instance.

    ``data`` holds the workflow-wide variables; ``scope`` is what expressions see (``data``
    itself, or a chain of ``data`` and the package-wide variables). ``parent`` is the activity
    instance of a synchronous subflow call waiting for this one.
    """

    __slots__ = (
        "data",
        "deferred",
        "depth",
        "frames",
        "id",
        "parent",
        "partner",
        "priority",
        "process",
        "root",
        "scope",
        "started_at",
        "state",
        "trigger",
        "view",
    )

    def __init__(self, id: int, process: CompiledProcess, data: dict[str, Any],
                 scope: MutableMapping[str, Any], priority: int,
                 parent: ActivityInstance | None, root: int, started_at: float,
                 state: int = NOT_STARTED, trigger: str | None = None) -> None:
        # (an object, as ActivityInstance.key: compiled, an ``int`` field is a C integer,
        # boxed anew at each use as the run's ``live`` table's key, found there by value;
        # boxed once here, its insertion and deletion use the one object)
        self.id: Any = id
        self.process = process
        self.data = data
        self.scope = scope
        self.state = state
        self.priority = priority
        self.parent = parent
        self.root = root
        self.frames: list[Frame] = []
        self.started_at = started_at
        # work that arrived while suspended (made when first needed: see :meth:`defer`)
        self.deferred: list[tuple[Any, ...]] | None = None
        self.trigger = trigger
        self.depth = 0                        # synchronous subflow calls above this one
        # the root instance whose message started this one (replies are correlated to it)
        self.partner: ProcessInstance | None = None
        # a read-only live view of ``data``, the work items' data (made at the first offer:
        # one per instance, not one per work item)
        self.view: Mapping[str, Any] | None = None

    def defer(self, item: tuple[Any, Any, Any, Any]) -> None:
        """Keep a ready-queue item until the suspended instance resumes."""
        if self.deferred is None:
            self.deferred = []
        self.deferred.append(item)

    def __repr__(self) -> str:
        return f"<ProcessInstance {self.process.id}#{self.id}>"


_NEW: Final[Callable[[type], Any]] = object.__new__


def process_instance(id: int, process: CompiledProcess, data: dict[str, Any],
                     scope: MutableMapping[str, Any], priority: int,
                     parent: ActivityInstance | None, root: int, started_at: float,
                     state: int, trigger: str | None) -> ProcessInstance:
    """From source, ``ProcessInstance(...)`` without calling the class (see
    :data:`PROCESS_FIELDS`): ``Flow.start_process``'s, two a dose cycle of the dispenser
    (the compiled engine calls the class)."""
    inst: Any = _NEW(ProcessInstance)
    inst.id = id
    inst.process = process
    inst.data = data
    inst.scope = scope
    inst.state = state
    inst.priority = priority
    inst.parent = parent
    inst.root = root
    inst.frames = []
    inst.started_at = started_at
    inst.deferred = None
    inst.trigger = trigger
    inst.depth = 0
    inst.partner = None
    inst.view = None
    made: ProcessInstance = inst
    return made


#: whether this module runs from source (then :func:`process_instance` is worth its call)
IN_LINE: Final = isinstance(process_instance, types.FunctionType)


class Frame:
    """Tokens of one instance moving through one graph (the process or an activity set).

    ``live`` counts tokens on their way (in the ready queue) plus activity instances running;
    ``parked`` counts tokens waiting at AND/OR joins; the frame is done when both are zero.
    """

    __slots__ = ("cjoins", "graph", "inst", "joins", "live", "ors", "owed", "owner", "parked",
                 "queue", "running")

    def __init__(self, graph: CompiledGraph, inst: ProcessInstance,
                 owner: ActivityInstance | None) -> None:
        self.graph = graph
        self.inst = inst
        self.owner = owner                    # the block activity instance, for activity sets
        self.live = 0
        self.parked = 0
        # AND / StartQuantity joins: tokens per incoming slot; OR joins likewise. Made when
        # the first token parks (most frames have no join; an empty dict each costs its
        # allocation and release per process instance)
        self.joins: dict[int, list[int]] | None = None
        self.ors: dict[int, list[int]] | None = None
        # (keyed by ``Any``, not ``int``: compiled, a deletion from a ``dict[int, ...]`` turns
        # its key into a C integer and boxes it anew, found then by value; the activity
        # instances' keys are boxed once, see ActivityInstance.__init__)
        self.running: dict[Any, ActivityInstance] = {}
        # complex joins: tokens per incoming slot, and the slots owed a token before the
        # join resets (after it fired; BPMN's "waiting for reset"); made when first needed
        # (a frame per instance: most never have a complex join)
        self.cjoins: dict[int, list[int]] | None = None
        self.owed: dict[int, set[int]] | None = None
        self.queue: list[int] | None = None   # sequential ad-hoc sets: starts still to run

    def and_joins(self) -> dict[int, list[int]]:
        """:attr:`joins`, made if need be."""
        if self.joins is None:
            self.joins = {}
        return self.joins

    def or_joins(self) -> dict[int, list[int]]:
        """:attr:`ors`, made if need be."""
        if self.ors is None:
            self.ors = {}
        return self.ors


class ActivityInstance:
    """An activity that takes time or waits: offered, running a subflow, catching an event,
    waiting for a worker, looping, under a deadline.

    ``gen`` is bumped whenever the instance stops waiting, so stale timer callbacks that still
    sit in SimPy's queue recognise they are obsolete (SimPy cannot cancel a scheduled event).
    """

    __slots__ = (
        "act",
        "child",
        "choice",
        "cleanup",
        "frame",
        "gen",
        "item",
        "iteration",
        "key",
        "local",
        "mi",
        "performer",
        "started_at",
        "state",
        "waiting",
    )

    def __init__(self, key: int, act: CompiledActivity, frame: Frame, started_at: float,
                 state: int = NOT_STARTED) -> None:
        # (an object, not an ``int``: compiled, an ``int`` field is a C integer, and each
        # read of it as a dictionary key would make a new Python int (ids pass 256 at
        # once), which the frame's running table then compares by value; boxed once here,
        # its insertion, test and deletion use the one object, found by identity)
        self.key: Any = key
        self.act = act
        self.frame = frame
        self.state = state
        self.started_at = started_at
        self.item: WorkItem | None = None
        self.child: Any = None                # ProcessInstance or Frame
        self.iteration = 0
        self.gen = 0
        self.waiting = ""                     # what it waits for, for deadlock reports
        self.choice: tuple[Any, ...] = ()     # deferred choice: the transitions offered
        # what undoes its armed waits when it leaves (made when the first is armed: most
        # activity instances arm none)
        self.cleanup: list[Callable[[], None]] | None = None
        self.performer: Any = None
        self.mi: MultiInstance | None = None
        # a collection multi-instance's own element ({elementVariable: item}), seen by this
        # instance only, over its process instance's data (see :meth:`scope`)
        self.local: dict[str, Any] | None = None

    def leave(self, state: int) -> None:
        """End this instance in ``state``: it stops waiting (``gen``: stale timers see it),
        leaves its frame's running set, and its cleanups (armed boundary events, deadlines,
        listeners) are undone. Completion, cancellation and a choice's losing branch all
        end an instance by these steps (``Activities._complete``, the completion of every
        activity instance, takes them in line)."""
        self.state = state
        self.gen += 1
        # (``in`` and ``del``, not ``pop(key, None)``: compiled, a dict's pop is a Python
        # method call, the others are primitives; the key is the one object boxed in
        # ``__init__``, found by identity, kept ``Any`` here: compiled, a local annotated
        # ``object`` was turned back into a C integer for the deletion and boxed anew)
        running = self.frame.running
        key = self.key
        if key in running:
            del running[key]
        if self.cleanup:
            self.undo_waits()

    def undo_waits(self) -> None:
        """Undo the armed waits (:meth:`leave`'s last step; ``Activities._complete`` takes
        the others in line)."""
        cleanup = self.cleanup
        if cleanup:
            for undo in cleanup:
                undo()
            cleanup.clear()

    def on_leave(self, undo: Callable[[], None]) -> None:
        """Call ``undo`` when this instance leaves (:meth:`leave`): an armed wait ends."""
        if self.cleanup is None:
            self.cleanup = []
        self.cleanup.append(undo)

    def scope(self) -> MutableMapping[str, Any]:
        """The data this instance reads: its process instance's, under its own element
        when it is one instance of a collection multi-instance. Writes go to the process
        instance's data (``set_field``), which the overlay shows through."""
        if self.local is None:
            return self.frame.inst.scope
        return ChainMap(self.local, self.frame.inst.scope)

    def __repr__(self) -> str:
        return f"<ActivityInstance {self.act.process}.{self.act.id}#{self.key}>"


class MultiInstance:
    """The instances of one multi-instance activity: ``count`` in all, ``started`` and
    ``completed`` so far, whether the token has ``passed`` on, and the ``members`` running.
    ``holder`` stands for the activity as a whole while any instance runs: its deadlines and
    boundary events are armed on it, once for all the instances (BPMN 2.0 §13.3.7)."""

    __slots__ = ("completed", "count", "holder", "items", "members", "passed", "started")

    def __init__(self, count: int, items: tuple[Any, ...] | None = None) -> None:
        self.count = count
        self.items = items            # a collection multi-instance's list, one item each
        self.started = 0
        self.completed = 0
        self.passed = False
        self.members: list[ActivityInstance] = []
        self.holder: ActivityInstance | None = None
