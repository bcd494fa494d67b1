"""Emulators: play a profile's device so a binding (or a prototype's host code) can be
developed and tested before the hardware exists.

:class:`EmulatedDevice` is the transport-free core: it answers command lines the way the
profile says the device does, with a scriptable :class:`Behaviour` (normal, silent, garbage,
late replies, a disconnect, a fixed error line). :class:`PtyEmulator` serves it on a
pseudo-terminal (``os.openpty()``; the binding opens the slave path like any serial port) and
:class:`SocketEmulator` on a ``socket://`` server. Both run one thread with a ``select`` loop,
accept unsolicited events from any thread (:meth:`send_event`) and stop cleanly.
"""

from __future__ import annotations

import heapq
import itertools
import os
import select
import socket
import threading
import time
import tty
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Final, Literal, Self

from opspec.bindings.profiles import DeviceProfile
from opspec.bindings.templates import TemplateError
from opspec.errors import BindingError

__all__ = [
    "DISCONNECT",
    "GARBAGE",
    "MAX_DELAY_S",
    "Behaviour",
    "EmulatedDevice",
    "PtyEmulator",
    "Reply",
    "SocketEmulator",
    "parse_event",
]

#: The longest wait the emulator takes (a late reply, an event's delay): a week. Beyond it (or
#: ``inf``, ``nan``) the select loop's timeout overflows and the emulator thread dies.
MAX_DELAY_S: Final = 7 * 86400.0


def _delay(text: str, scale: float = 1.0) -> float:
    """``text`` (a number) times ``scale`` as seconds; ValueError unless 0 to MAX_DELAY_S."""
    value = float(text) * scale
    if not 0.0 <= value <= MAX_DELAY_S:        # nan compares false: refused too
        raise ValueError(text)
    return value


def parse_event(spec: str, option: str = "--event") -> tuple[str, float]:
    """``NAME@SECONDS`` (``--event``, ``emulator://…?event=``): the event's name and how many
    seconds from now it is sent; BindingError naming ``option`` for a bad delay."""
    name, _, after = spec.partition("@")
    try:
        return name, _delay(after or "0")
    except ValueError:
        raise BindingError(f"{option} {spec!r}: expected NAME@SECONDS, e.g. report@5",
                           hint=f"SECONDS is a number from 0 to {MAX_DELAY_S:,.0f} "
                           "(a week)") from None


BehaviourKind = Literal["none", "silent", "garbage", "late", "disconnect", "error"]
#: What the ``garbage`` behaviour sends: undecodable bytes and no known reply.
GARBAGE: Final = b"\xfe\x15%$GARBLED$%\x07"


@dataclass(frozen=True, slots=True)
class Behaviour:
    """How the emulated device misbehaves.

    * ``none``: replies per profile;
    * ``silent[:N]``: no reply to the first N commands (all if N is omitted);
    * ``garbage[:N]``: a garbled line instead of the reply to the first N (or all) commands;
    * ``late:MS``: every reply MS milliseconds late;
    * ``disconnect:N``: answers N commands, then drops the line on the next one (once);
    * ``error:LINE``: replies LINE (``error:ERR JAM``) to every command.
    """

    kind: BehaviourKind = "none"
    count: int | None = None
    delay_s: float = 0.0
    line: str = ""

    @classmethod
    def parse(cls, spec: str) -> Behaviour:
        """Parse ``--fault`` text; raise BindingError explaining the accepted forms."""
        kind, _, arg = spec.strip().partition(":")
        usage = "use none, silent[:N], garbage[:N], late:MS, disconnect:N or error:LINE"
        try:
            if kind == "none" and not arg:
                return cls()
            if kind in ("silent", "garbage"):
                return cls(kind, count=_count(arg) if arg else None)  # type: ignore[arg-type]
            if kind == "late":
                return cls("late", delay_s=_delay(arg, 1e-3))
            if kind == "disconnect":
                return cls("disconnect", count=_count(arg))
            if kind == "error" and arg:
                return cls("error", line=arg)
        except ValueError:
            pass
        raise BindingError(f"unknown emulator fault {spec!r}", hint=f"{usage}; N is a whole "
                           f"number >= 0, MS from 0 to {MAX_DELAY_S * 1000:,.0f}")

    def describe(self) -> str:
        if self.kind == "late":
            return f"late:{self.delay_s * 1000:g}"
        if self.kind == "error":
            return f"error:{self.line}"
        return self.kind if self.count is None else f"{self.kind}:{self.count}"


def _count(text: str) -> int:
    value = int(text)
    if value < 0:
        raise ValueError(text)
    return value


@dataclass(frozen=True, slots=True)
class Reply:
    """Bytes to send, ``delay_s`` seconds after the command arrived."""

    data: bytes
    delay_s: float = 0.0


class _Disconnect:
    def __repr__(self) -> str:
        return "DISCONNECT"


#: The action that drops the line.
DISCONNECT: Final = _Disconnect()
Action = Reply | _Disconnect


class EmulatedDevice:
    """The device logic: command lines in, actions out. Not thread-safe; one owner thread."""

    def __init__(self, profile: DeviceProfile, behaviour: Behaviour = Behaviour()) -> None:
        self.profile = profile
        self.behaviour = behaviour
        self.commands = 0
        self._newline = profile.serial.newline.encode()
        self._disconnected_once = False

    def encode(self, text: str) -> bytes:
        return text.encode(self.profile.serial.encoding, "replace") + self._newline

    def reply_text(self, line: str) -> str:
        """What the well-behaved device answers to ``line``."""
        for op in self.profile.operations.values():
            if op.command is None:
                continue
            values = op.command.match(line)
            if values is None:
                continue
            template = op.emulate_reply or op.ok[0]
            try:
                return template.fill({**op.defaults, **op.emulate_values, **values})
            except TemplateError:
                return self.profile.emulator_unknown_reply
        return self.profile.emulator_unknown_reply

    def handle_line(self, line: str) -> list[Action]:
        """Actions answering one received command line (terminator already stripped)."""
        self.commands += 1
        n, b = self.commands, self.behaviour
        first_n = b.count is None or n <= b.count
        if b.kind == "silent" and first_n:
            return []
        if b.kind == "garbage" and first_n:
            return [Reply(GARBAGE + self._newline)]
        if b.kind == "disconnect" and b.count is not None and n > b.count \
                and not self._disconnected_once:
            self._disconnected_once = True
            return [DISCONNECT]
        if b.kind == "error":
            return [Reply(self.encode(b.line))]
        return [Reply(self.encode(self.reply_text(line)), b.delay_s)]

    def event_line(self, name: str, values: Mapping[str, Any] | None = None) -> bytes:
        """The unsolicited line of event ``name`` (values from the profile's ``emulate``)."""
        try:
            rule = self.profile.events[name]
        except KeyError:
            known = ", ".join(self.profile.events) or "none"
            raise BindingError(f"profile {self.profile.name!r} has no event {name!r}",
                               hint=f"events: {known}") from None
        try:
            return self.encode(rule.line.fill({**rule.emulate_values, **(values or {})}))
        except TemplateError as error:
            raise BindingError(f"event {name!r}: {error}",
                               hint=f"give values in [events.{name}.emulate]") from None


class _Server(threading.Thread):
    """A select loop: reads command lines, writes (possibly delayed) replies, injects events."""

    def __init__(self, device: EmulatedDevice, name: str) -> None:
        super().__init__(name=name, daemon=True)
        self.device = device
        self.received: list[str] = []        # every command line, in order (for tests/logs)
        self.connected = threading.Event()    # a client is (or was) connected
        self.dropped = threading.Event()      # the emulator dropped the line (disconnect)
        self._lock = threading.Lock()
        self._wake_r, self._wake_w = os.pipe()
        self._stopping = False
        self._buffer = bytearray()
        self._outbox: list[tuple[float, int, bytes]] = []   # (due, seq, data), a heap
        self._injected: list[tuple[float, int, bytes]] = []  # posted by other threads
        self._seq = itertools.count()
        #: Called on the emulator's thread with ``"<- line"`` / ``"-> line"`` / notes.
        self.log: Callable[[str], None] | None = None

    # -- called from any thread
    def send_event(self, name: str, after_s: float = 0.0,
                   values: Mapping[str, Any] | None = None) -> None:
        """Send event ``name``'s line now or ``after_s`` seconds from now."""
        data = self.device.event_line(name, values)
        with self._lock:
            self._injected.append((_now() + after_s, next(self._seq), data))
        os.write(self._wake_w, b"x")

    def stop(self) -> None:
        """Stop serving and release the port; safe to call twice."""
        self._stopping = True
        try:
            os.write(self._wake_w, b"x")
        except OSError:
            pass
        if self.is_alive() and threading.current_thread() is not self:
            self.join(5)

    def __enter__(self) -> Self:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- subclass hooks (loop thread only)
    def _read_fds(self) -> list[int]:
        raise NotImplementedError

    def _on_readable(self, fd: int) -> None:
        raise NotImplementedError

    def _send(self, data: bytes) -> None:
        raise NotImplementedError

    def _drop(self) -> None:
        raise NotImplementedError

    def _close(self) -> None:
        raise NotImplementedError

    # -- the loop
    def _feed(self, data: bytes) -> None:
        self._buffer.extend(data)
        while True:
            cut = self._buffer.find(b"\n")
            cut_r = self._buffer.find(b"\r")
            if cut < 0 or (0 <= cut_r < cut and self.device.profile.serial.newline == "\r"):
                cut = cut_r
            if cut < 0:
                return
            raw = bytes(self._buffer[:cut])
            del self._buffer[:cut + 1]
            line = raw.decode(self.device.profile.serial.encoding, "replace").strip()
            if not line:
                continue
            self.received.append(line)
            self._log(f"<- {line}")
            for action in self.device.handle_line(line):
                if isinstance(action, Reply):
                    late = f" (in {action.delay_s * 1000:g} ms)" if action.delay_s else ""
                    self._log(f"-> {action.data.decode('ascii', 'backslashreplace').rstrip()}{late}")
                    heapq.heappush(self._outbox, (_now() + action.delay_s, next(self._seq),
                                                  action.data))
                else:
                    self._log("-- dropping the line (disconnect)")
                    self._outbox.clear()
                    self.dropped.set()
                    self._drop()
                    return

    def _log(self, text: str) -> None:
        if self.log is not None:
            self.log(text)

    def run(self) -> None:
        try:
            while not self._stopping:
                with self._lock:
                    for entry in self._injected:
                        heapq.heappush(self._outbox, entry)
                    self._injected.clear()
                now = _now()
                while self._outbox and self._outbox[0][0] <= now:
                    self._send(heapq.heappop(self._outbox)[2])
                timeout = max(0.0, self._outbox[0][0] - now) if self._outbox else None
                fds = [self._wake_r, *self._read_fds()]
                ready, _, _ = select.select(fds, [], [], timeout)
                for fd in ready:
                    if fd == self._wake_r:
                        os.read(self._wake_r, 4096)
                    else:
                        self._on_readable(fd)
        finally:
            self._close()
            for fd in (self._wake_r, self._wake_w):
                try:
                    os.close(fd)
                except OSError:
                    pass


def _now() -> float:
    return time.monotonic()


class PtyEmulator(_Server):
    """The device on a pseudo-terminal pair. :attr:`path` is the slave to open (``/dev/pts/N``).

    A ``disconnect`` closes the master: the slave path disappears, like an unplugged USB
    adapter, so reopening it fails. The emulator keeps its slave descriptor until
    :meth:`stop`, so the kernel cannot hand the same ``/dev/pts/N`` to another process
    meanwhile (which would let a reconnect reach a stranger's terminal).
    """

    def __init__(self, device: EmulatedDevice) -> None:
        super().__init__(device, f"pty-emulator-{device.profile.name}")
        try:
            self._master, self._slave = os.openpty()
        except OSError as error:
            raise BindingError(f"cannot create a pseudo-terminal: {error.strerror}") from None
        # raw: no echo, no newline translation; the binding's pyserial does the same on open
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self._open = True
        self.connected.set()

    @property
    def url(self) -> str:
        return self.path

    def _read_fds(self) -> list[int]:
        return [self._master] if self._open else []

    def _on_readable(self, fd: int) -> None:
        try:
            data = os.read(fd, 4096)
        except OSError:  # EIO: nobody holds the slave; keep waiting for an opener
            data = b""
        if data:
            self._feed(data)

    def _send(self, data: bytes) -> None:
        if self._open:
            os.write(self._master, data)

    def _drop(self) -> None:
        if self._open:
            self._open = False
            os.close(self._master)

    def _close(self) -> None:
        self._drop()
        if self._slave >= 0:
            os.close(self._slave)
            self._slave = -1


class SocketEmulator(_Server):
    """The device on a TCP server (``socket://HOST:PORT``), one client at a time. Port 0
    picks a free port; :attr:`url` says which. A ``disconnect`` closes the client's
    connection but keeps listening, so a binding can reconnect."""

    def __init__(self, device: EmulatedDevice, host: str = "127.0.0.1", port: int = 0) -> None:
        if not 0 <= port <= 65535:      # socket raises OverflowError, not OSError, for these
            raise BindingError(f"cannot listen on {host}:{port}: a TCP port is 0 to 65535",
                               hint="port 0 picks a free port")
        super().__init__(device, f"socket-emulator-{device.profile.name}")
        try:
            self._listener = socket.create_server((host, port))
        except OSError as error:
            import errno

            hint = {errno.EADDRINUSE: ("another program listens on that port: choose another "
                                       "port, or port 0 for a free one "
                                       "(socket://127.0.0.1:0)"),
                    errno.EADDRNOTAVAIL: (f"{host} is not an address of this machine: use "
                                          "127.0.0.1, or 0.0.0.0 for every address")
                    }.get(error.errno or 0, "")
            # (os.strerror: create_server's strerror adds "while attempting to bind on …")
            reason = os.strerror(error.errno) if error.errno else str(error)
            raise BindingError(f"cannot listen on {host}:{port}: {reason}",
                               hint=hint) from None
        self.host, self.port = self._listener.getsockname()[:2]
        self._client: socket.socket | None = None

    @property
    def url(self) -> str:
        return f"socket://{self.host}:{self.port}"

    def _read_fds(self) -> list[int]:
        fds = [self._listener.fileno()]
        if self._client is not None:
            fds.append(self._client.fileno())
        return fds

    def _on_readable(self, fd: int) -> None:
        if fd == self._listener.fileno():
            client, _ = self._listener.accept()
            if self._client is not None:  # one client at a time: the newest wins
                self._client.close()
            self._client = client
            self._buffer.clear()
            self.connected.set()
            return
        if self._client is None or fd != self._client.fileno():
            return  # dropped earlier in this round
        try:
            data = self._client.recv(4096)
        except OSError:
            data = b""
        if data:
            self._feed(data)
        else:
            self._drop()

    def _send(self, data: bytes) -> None:
        if self._client is not None:
            try:
                self._client.sendall(data)
            except OSError:
                self._drop()

    def _drop(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None

    def _close(self) -> None:
        self._drop()
        self._listener.close()
