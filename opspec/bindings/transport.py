"""Transports: opening ports by URL, listing real ports, and line framing on a reader thread.

Every port is opened with ``serial.serial_for_url``, so ``/dev/ttyUSB0``, ``loop://``,
``socket://host:port``, ``rfc2217://host:port`` and opspec's own ``emulator://PROFILE``
(an in-process scripted device, see :mod:`opspec.bindings.urlhandler.protocol_emulator`)
all work the same way. Framing is a :class:`serial.threaded.Packetizer` subclass run by a
:class:`serial.threaded.ReaderThread`; it calls back *on the reader thread*, so its owner
must only post into an :class:`~opspec.bindings.inbox.Inbox` from there.
"""

from __future__ import annotations

import errno
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import serial
import serial.threaded
import serial.tools.list_ports

from opspec.bindings.profiles import DeviceProfile, PortMatch, SerialSettings
from opspec.errors import BindingError

__all__ = [
    "LineFramer",
    "LineReaderThread",
    "PortInfo",
    "find_port",
    "list_ports",
    "open_port",
    "register_url_handlers",
    "settles",
]

_HANDLER_PACKAGE = "opspec.bindings.urlhandler"
_POLL_S = 0.05  # read timeout for transports that cannot cancel a blocking read


def register_url_handlers() -> None:
    """Make ``emulator://`` known to ``serial_for_url`` (idempotent)."""
    if _HANDLER_PACKAGE not in serial.protocol_handler_packages:
        serial.protocol_handler_packages.append(_HANDLER_PACKAGE)


register_url_handlers()


def settles(url: str) -> bool:
    """Whether the device at ``url`` is waited for after it is opened (the profile's
    ``settle_ms``): a device path of a board, which resets when its port opens and drops
    what it is sent meanwhile; not a pySerial URL (``socket://``, ``emulator://``), nor a
    pseudo-terminal (``opspec devices emulate``'s, a socat pair), which resets nothing."""
    if "://" in url:
        return False
    import re

    real = os.path.realpath(url)
    return not (real.startswith("/dev/pts/") or re.fullmatch(r"/dev/ttys\d+", real))


def open_port(url: str, settings: SerialSettings, who: str = "",
              profiles_dir: str | os.PathLike[str] | None = None) -> serial.Serial:
    """Open ``url`` with the profile's settings, or raise BindingError naming the port and
    the reason (the operating system's words, e.g. ``[Errno 2] No such file or directory``).

    A device path is opened for this process alone (POSIX ``flock``, as pySerial's
    ``exclusive``): a second run bound to the same board would otherwise read half of the
    first one's replies, and both would report garbage instead of a busy port.
    ``profiles_dir``: where ``emulator://PROFILE`` looks a profile name up first (the folder
    of the bound profile, i.e. ``--devices``)."""
    prefix = f"{who}: " if who else ""
    extra: dict[str, Any] = {}
    if "://" not in url:
        extra["exclusive"] = True
    elif url.startswith("emulator://") and profiles_dir is not None:
        extra["profiles_dir"] = profiles_dir
    try:
        # every URL handler's class offers the serial.Serial API; the stubs say SerialBase
        port: serial.Serial = serial.serial_for_url(
            url, baudrate=settings.baudrate, bytesize=settings.bytesize,
            parity=settings.parity, stopbits=settings.stopbits, timeout=_POLL_S,
            write_timeout=max(1.0, settings.reply_timeout_s), **extra,
        )
    except ValueError as error:  # unknown URL scheme, bad option in the URL
        raise BindingError(f"{prefix}cannot open {url}: {error}",
                           hint="use a device path, loop://, socket://HOST:PORT, "
                           "rfc2217://HOST:PORT or emulator://PROFILE") from None
    except (serial.SerialException, OSError) as error:
        if _locked(error):
            raise BindingError(f"{prefix}cannot open {url}: it is in use by another program",
                               hint="close the other program that has the port open (another "
                               "opspec run, a serial monitor) and try again") from None
        raise BindingError(f"{prefix}cannot open {url}: {_reason(error)}",
                           hint=_open_hint(url)) from None
    except Exception as error:  # noqa: BLE001 - e.g. termios.error from a dying pty
        raise BindingError(f"{prefix}cannot open {url}: {type(error).__name__}: {error}",
                           hint="the port vanished or is not a serial device") from None
    return port


def _locked(error: BaseException) -> bool:
    """Whether opening failed because another process holds the port's exclusive lock."""
    return (getattr(error, "errno", None) in (errno.EAGAIN, errno.EWOULDBLOCK)
            and "exclusively lock" in str(error))


def _open_hint(url: str) -> str:
    """What to check when ``url`` would not open: a cable and permissions for a device path,
    a listening server for a network URL, the URL itself for an emulator."""
    scheme = url.split("://", 1)[0].lower() if "://" in url else ""
    if scheme in ("socket", "rfc2217"):
        return ("check that a device server (or `opspec devices emulate PROFILE --port "
                "socket://HOST:PORT`) is listening at that host and port")
    if scheme == "emulator":
        return ("write emulator://PROFILE (a profile name or .toml path) with optional "
                "?fault=SPEC&event=NAME@SECONDS; see devices/README.md")
    return ("check the cable and the path (`opspec devices list`), and that you may use "
            "the port (e.g. membership of the dialout group)")


def _reason(error: BaseException) -> str:
    text = str(error)
    # pyserial repeats itself: "[Errno 2] could not open port X: [Errno 2] No such file…",
    # and socket:// "Could not open port socket://…: [Errno 111] Connection refused"
    if "could not open port" in text.lower() and ": [Errno" in text:
        text = text[text.rindex(": [Errno") + 2:]
    return text


@dataclass(frozen=True, slots=True)
class PortInfo:
    """A real port as the operating system lists it (virtual ports never appear)."""

    device: str
    description: str
    hwid: str
    vid: int | None = None
    pid: int | None = None
    serial_number: str | None = None

    def matches(self, rules: PortMatch) -> bool:
        return rules.matches(self.vid, self.pid, self.serial_number, self.description)


def list_ports() -> list[PortInfo]:
    """``serial.tools.list_ports.comports()`` as plain data, sorted by device path."""
    return sorted(
        (PortInfo(p.device, p.description or "", p.hwid or "", p.vid, p.pid, p.serial_number)
         for p in serial.tools.list_ports.comports()),
        key=lambda p: p.device,
    )


def find_port(profile: DeviceProfile, ports: Sequence[PortInfo] | None = None
              ) -> tuple[str | None, str]:
    """The port ``auto`` binds ``profile`` to, and a note saying how it was chosen.

    The profile's explicit ``port.url`` wins; otherwise the first listed port matching every
    rule. ``(None, note)`` when nothing matches; the note names the rules.
    """
    rules = profile.port
    if rules.url is not None:
        return rules.url, f"{profile.name}: using the profile's port {rules.url}"
    if not rules.has_rules:
        return None, f"{profile.name}: the profile has no [port] rules to match"
    found = [p for p in (list_ports() if ports is None else ports) if p.matches(rules)]
    if not found:
        return None, f"no device matched {rules.describe()}"
    note = f"{profile.name}: {found[0].device} matched {rules.describe()}"
    if len(found) > 1:
        others = ", ".join(p.device for p in found[1:])
        note += f" (also matched, not used: {others})"
    return found[0].device, note


class LineFramer(serial.threaded.Packetizer):
    """Split received bytes into lines (``\\n``, ``\\r\\n`` or ``\\r`` per the profile).

    Calls ``on_line(text, received_at)`` with trailing whitespace stripped, or
    ``on_garbage(raw, received_at, why)`` for a line that cannot be decoded or that exceeds
    ``max_line_bytes`` without a terminator, and ``on_lost(exception_or_None)`` once when
    the reader stops. ``received_at`` is ``time.perf_counter()`` on the reader thread, so
    latencies do not include the engine's drain delay.
    """

    def __init__(self, settings: SerialSettings,
                 on_line: Callable[[str, float], None],
                 on_garbage: Callable[[bytes, float, str], None],
                 on_lost: Callable[[BaseException | None], None]) -> None:
        super().__init__()
        # "\r\n" ends in "\n": split on the last byte and strip the rest
        self.TERMINATOR = settings.newline[-1].encode()
        self.encoding = settings.encoding
        self.max_line = settings.max_line_bytes
        self.on_line, self.on_garbage, self.on_lost = on_line, on_garbage, on_lost

    def data_received(self, data: bytes) -> None:
        super().data_received(data)
        if len(self.buffer) > self.max_line:
            raw = bytes(self.buffer)
            del self.buffer[:]
            self.on_garbage(raw, time.perf_counter(),
                            f"no line terminator within {self.max_line} bytes")

    def handle_packet(self, packet: bytes) -> None:
        at = time.perf_counter()
        try:
            text = packet.decode(self.encoding).strip()
        except UnicodeDecodeError:
            self.on_garbage(bytes(packet), at, f"not {self.encoding} text")
            return
        if text and not text.isprintable():
            self.on_garbage(bytes(packet), at, "control characters in the line")
        elif text:
            self.on_line(text, at)

    def connection_lost(self, exc: BaseException | None) -> None:
        self.transport = None
        self.on_lost(exc)  # never re-raise on the reader thread: the binding reports it


class LineReaderThread(serial.threaded.ReaderThread):
    """ReaderThread that stops within ``_POLL_S`` on transports without ``cancel_read``
    (``socket://``, ``loop://``), instead of the base class's one second."""

    def run(self) -> None:
        if not hasattr(self.serial, "cancel_read"):
            self.serial.timeout = _POLL_S
        self.protocol = self.protocol_factory()
        self.protocol.connection_made(self)
        self._connection_made.set()  # type: ignore[attr-defined]  # the base class's
        error: BaseException | None = None
        while self.alive and self.serial.is_open:
            try:
                data = self.serial.read(self.serial.in_waiting or 1)
            except (serial.SerialException, OSError, TypeError) as exc:
                # SerialException: a vanished device (is_open stays True); TypeError/OSError:
                # the port was closed under us by close() on another thread
                error = exc
                break
            if data:
                self.protocol.data_received(data)
        self.alive = False
        self.protocol.connection_lost(error)
        self.protocol = None  # type: ignore[assignment]  # as the base class does

    def shutdown(self) -> None:
        """Stop reading and close the port; never raises, never blocks for long."""
        self.alive = False
        cancel = getattr(self.serial, "cancel_read", None)
        if cancel is not None:
            try:
                cancel()
            except (serial.SerialException, OSError, TypeError):
                pass
        if self.is_alive() and self is not _current():
            self.join(2)
        try:
            self.serial.close()
        except (serial.SerialException, OSError, TypeError):
            pass


def _current() -> object:
    return threading.current_thread()
