"""What a device binding holds, and how it reports: the state every part of
:class:`~opspec.bindings.binding.DeviceBinding` shares (its profile, participants, port and
their modes; the commands queued, in flight, timed out or held), the kinds of trace event it
writes, and its faults and notes.

The parts are mixins of one object, all run on the engine's thread (see the
:mod:`~opspec.bindings.binding` docstring): the line protocol (:mod:`.exchanges`), the port
and its reconnection (:mod:`.reconnection`) and the profile's fallback (:mod:`.fallback`).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Final, Literal

from opspec.bindings.inbox import Inbox
from opspec.bindings.profiles import DeviceProfile, Operation
from opspec.bindings.simulated import ProfileSimulator
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.trace import EventKind

if TYPE_CHECKING:
    import serial

    from opspec.bindings.transport import LineReaderThread

__all__ = ["DEVICE_EVENT", "DEVICE_EXCHANGE", "DEVICE_NOTE", "DEVICE_PENDING", "BindingState",
           "Connection", "Job", "Mode"]

DEVICE_EXCHANGE: Final = "device.exchange"   # a command and its reply, with latency
DEVICE_NOTE: Final = "device.note"           # bound / simulated / reconnected / switched
DEVICE_EVENT: Final = "device.event"         # an unsolicited line the profile knows
DEVICE_PENDING: Final = "device.pending"     # work unfinished when the run ended

Mode = Literal["device", "simulated", "aborted"]
Connection = Literal["open", "reconnecting", "gone", "closed", "none"]


@dataclass(eq=False, slots=True)
class Job:
    """One command for one work item, possibly sent several times."""

    item: WorkItem
    op: Operation
    line: str
    attempts: int = 0
    seq: int = 0
    sent_at: float = 0.0
    timer: threading.Timer | None = None
    withdrawn: bool = False
    last_fault: str = ""
    # what the device sent during this attempt that was not its reply, as (fault, message):
    # the attempt goes on, since a valid reply may still follow (noise lines, a partial
    # frame); reported with the reply, or as the attempt's failure at its timeout
    noise: list[tuple[str, str]] = field(default_factory=list)


class BindingState:
    """The state of a :class:`~opspec.bindings.binding.DeviceBinding` and its reporting;
    the arguments are the binding's (see there)."""

    def __init__(self, profile: DeviceProfile, participants: Sequence[str], url: str | None,
                 port: serial.Serial | None, *, inbox: Inbox | None = None,
                 notes: Sequence[str] = ()) -> None:
        self.profile = profile
        self.participants: tuple[str, ...] = tuple(participants)
        self.url = url
        self.inbox = inbox if inbox is not None else Inbox()
        self.notes: list[str] = list(notes)
        #: Round-trip time of every answered command, in seconds (wall clock).
        self.latencies: list[float] = []
        #: The data of every fault reported, in order (also in the trace), plus ``at``: the
        #: simulated time it was reported (None before :meth:`attach`).
        self.faults: list[dict[str, Any]] = []
        #: participant id → the binding of the same run that serves it (set by
        #: :class:`~opspec.bindings.attach.AttachedDevices`): the engine routes each
        #: Application id to one binding, whichever registered it last, so work for a
        #: participant bound elsewhere is passed on (see ``DeviceBinding.offer``).
        self.peers: Mapping[str, Any] = {}
        self._session: PerformerSession | None = None
        self._sim = ProfileSimulator(profile)
        start: Mode = "device" if port is not None else "simulated"
        self._modes: dict[str, Mode] = {p: start for p in self.participants}
        self._port = port
        self._reader: LineReaderThread | None = None
        self._connection: Connection = "open" if port is not None else "none"
        self._generation = 0
        self._queue: deque[Job] = deque()
        self._inflight: Job | None = None
        self._waiting: list[WorkItem] = []          # passive operations awaiting an event
        self._timed_out: deque[Job] = deque()       # replies we gave up waiting for
        # after a timeout the line is held (nothing is sent) until the late reply comes or
        # the late-reply window passes; ``_resend`` is the job to send again then, if any
        self._held: Job | None = None
        self._resend: Job | None = None
        self._hold_timer: threading.Timer | None = None
        self._holds = 0
        self._seq = 0
        self._closed = threading.Event()
        self._newline = profile.serial.newline.encode()

    def mode(self, participant: str | None) -> Mode:
        """``device``, ``simulated`` or ``aborted`` for ``participant``."""
        return self._modes.get(participant or "", "device" if self._port else "simulated")

    # ------------------------------------------------------------------ reporting
    def _fault(self, fault: str, message: str, *, item: WorkItem | None = None,
               action: str = "none", line: str | None = None, **extra: Any) -> None:
        data: dict[str, Any] = {"fault": fault, "device": self.profile.name, "port": self.url,
                                "message": message, "action": action}
        if item is not None:
            data.update(participant=item.participant, activity=item.activity,
                        instance=item.instance, item=item.key)
        if line is not None:
            data["command"] = line
        data.update(extra)
        # the report gives each fault's simulated time (the trace event carries it already)
        self.faults.append({**data, "at": self._session.now if self._session else None})
        if self._session is not None:
            self._session.trace(EventKind.FAULT, data)

    def _note(self, message: str) -> None:
        if message not in self.notes:
            self.notes.append(message)
        if self._session is not None:
            self._session.trace(DEVICE_NOTE, {"device": self.profile.name, "port": self.url,
                                              "message": message})

    def _session_(self) -> PerformerSession:
        if self._session is None:
            raise RuntimeError(f"DeviceBinding for {self._label()} used before attach()")
        return self._session

    def _who(self, item: WorkItem) -> str:
        return item.participant or self._label()

    def _label(self) -> str:
        return ", ".join(self.participants) or self.profile.name

    if TYPE_CHECKING:   # the parts of DeviceBinding call each other: these are theirs
        def _pump(self) -> None: ...
        def _on_line(self, gen: int, text: str, at: float) -> None: ...
        def _on_garbage(self, gen: int, raw: bytes, why: str) -> None: ...
        def _end_hold(self) -> None: ...
        def _start_reader(self, port: serial.Serial) -> None: ...
        def _disconnected(self, exc: BaseException | None, doing: str) -> None: ...
        def _give_up(self, job: Job, reason: str) -> None: ...
        def _switch_to_simulated(self, participant: str, reason: str) -> None: ...
        def _reroute(self, job: Job) -> None: ...
