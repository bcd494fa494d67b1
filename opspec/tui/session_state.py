"""What every part of a walkthrough session shares: its state (the clock's pace and the
call in progress, the offers, what is running, the device board, the recording's steps,
the failure that ended the run), set up before the run is built, and :func:`guarded`, which
ends the session when the engine fails in a method that steps it.

:class:`~opspec.tui.session.WalkSession` is one object made of parts, each a mixin over this
state: the clock (:mod:`.session_clock`), the person's lane (:mod:`.session_lane`), the trace
followed (:mod:`.session_events`) and the recording (:mod:`.session_record`).
"""

from __future__ import annotations

import functools
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from opspec.engine.compiled import CompiledPackage
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError, ExecutionError
from opspec.tui.devices import DeviceBoard
from opspec.tui.lane import Offer
from opspec.tui.timing import OfferTimes, Response

if TYPE_CHECKING:
    from pathlib import Path

    from opspec.engine.performers import WorkItem
    from opspec.engine.simulation import Simulation
    from opspec.engine.trace_sinks import JsonlSink
    from opspec.runs import Run, RunOutcome
    from opspec.tui.feedback import Aftermath
    from opspec.tui.lane import LaneUser

__all__ = ["ON_CALL", "SessionState", "guarded"]

#: what the clock does when the device calls the person (``--on-call``)
ON_CALL = ("realtime", "pause", "keep")

_F = TypeVar("_F", bound=Callable[..., Any])


def guarded(default: Any = None) -> Callable[[_F], _F]:
    """Methods that step the engine: an ExecutionError ends the session (see
    :meth:`~opspec.tui.session.WalkSession._fail`) and the method returns ``default``."""
    def wrap(method: _F) -> _F:
        @functools.wraps(method)
        def guarded_method(self: SessionState, *args: Any, **kwargs: Any) -> Any:
            if self.failure is not None:
                return default
            try:
                return method(self, *args, **kwargs)
            except ExecutionError as error:
                self._fail(error)
                return default
        return guarded_method  # type: ignore[return-value]
    return wrap


class SessionState:
    """The state of a :class:`~opspec.tui.session.WalkSession` (the arguments are the
    session's; see there)."""

    # set by WalkSession as it reads the spec's activities and builds the run
    _deadline_of: dict[tuple[str, str], Any]
    _names: dict[tuple[str, str], str]
    aftermath: Aftermath
    device_signals: bool
    has_user_lane: bool
    lane_user: LaneUser
    run: Run
    sim: Simulation
    # the recording (session_record)
    record_path: Path | None
    _steps: list[list[str]]
    _trace_file: JsonlSink | None
    _closing: list[Callable[[], object]]
    _quit: bool

    def __init__(self, compiled: CompiledPackage, *, seed: int, days: float | None,
                 until: float | None, model_factory: Callable[[], Any] | None, replay: Any, spec_path: str,
                 device_participants: Mapping[str, Sequence[str]] | None,
                 wall_devices: bool, on_call: str, person: str | None) -> None:
        from opspec.run_rules import check_seed, run_length

        self.compiled = compiled
        self.seed = check_seed(seed)
        #: where the run ends: the one rule of every run (opspec.runs.run_length): ``days``
        #: (or ``until``, in seconds), else the spec's opspec:RunLength, else one day
        self.horizon = run_length(compiled, days=days, until=until)
        if on_call not in ON_CALL:
            raise ConfigurationError(f"--on-call takes one of {', '.join(ON_CALL)}, not "
                                     f"{on_call!r}")
        self.on_call = on_call
        #: when each offer reached the person, and whether the clock ran in real time since
        self.times = OfferTimes()
        self._speed = 60.0
        self._paused = False
        #: the speed the person had before a call dropped the clock to real time
        self._speed_before_call: float | None = None
        #: --on-call pause paused the clock for this call (the person has not resumed it)
        self._call_paused = False
        self._in_call = False                # the device calls the person now
        self._acted_in_call = False          # ... and the person has answered something
        self._call_began = False             # set by an event: stop stepping, apply on_call
        #: the person's actions with their response times (the end-of-run summary)
        self.responses: list[Response] = []
        self.model_factory = model_factory
        self.events: deque[TraceEvent] = deque(maxlen=2000)
        self.listeners: list[Callable[[TraceEvent], None]] = []
        self.deadlines: dict[tuple[int, str], float] = {}   # (instance, activity) -> due time
        self.current: dict[int, tuple[str, str]] = {}       # instance -> (process, activity)
        self.participants: dict[str, str] = {}              # participant -> last action
        #: each device participant's state (ringing, busy, last done, display, fault)
        self.board = DeviceBoard(compiled, device_participants)
        self.replaying = replay is not None
        #: real devices are bound: their answers come in wall time (see waiting_for_devices)
        self.wall_devices = wall_devices
        self.device_work: set[tuple[int, str]] = set()      # offered to a device, unanswered
        self.skipping = False                               # a skip until the user goes on
        self._skip_calls = 0                                # self.calls when it began
        self.calls = 0                                      # user-lane processes started
        #: what the person can do now, oldest first (offers of an instance that ended, or
        #: superseded by the same activity offered in a newer instance, are gone)
        self.offers: list[Offer] = []
        self.lapsed = 0                                     # offers superseded so far
        self._offer_seq = 0                                 # offers made so far
        self._seq_of: dict[int, int] = {}                   # item key -> its offer number
        self._skip_from = 0                                 # _offer_seq when the skip began
        self.ended = False
        #: instances whose every offer to the person lapsed (not shown as running)
        self.lapsed_instances: set[int] = set()
        #: the error that ended the run (a zero-time cycle...), or None
        self.failure: ExecutionError | None = None
        self.spec_path = spec_path
        self.person = person
        self._outcome: RunOutcome | None = None

    if TYPE_CHECKING:   # the parts of WalkSession call each other: these are theirs
        @property
        def now(self) -> float: ...
        @property
        def speed(self) -> float: ...
        @speed.setter
        def speed(self, value: float) -> None: ...
        @property
        def paused(self) -> bool: ...
        @paused.setter
        def paused(self, value: bool) -> None: ...
        @property
        def calling(self) -> bool: ...
        @property
        def person_performs(self) -> bool: ...
        @property
        def handed_over(self) -> bool: ...
        def _fail(self, error: ExecutionError) -> None: ...
        def _follow_call(self) -> None: ...
        def has_new_offers(self, since: int) -> bool: ...
        def _offered(self, item: WorkItem) -> None: ...
        def _drop_offers(self, *keys: int) -> None: ...
        def _drop_instance(self, instance: int) -> None: ...
        def _label_of(self, process: str, activity: str) -> str: ...
        def _on_event(self, event: TraceEvent) -> None: ...
        def _trace_run_ended(self) -> None: ...
        def _record(self, action: str, *, by: str, item: WorkItem | None = None,
                    label: str = "") -> None: ...
