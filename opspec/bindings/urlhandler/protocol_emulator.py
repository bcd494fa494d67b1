"""``emulator://PROFILE[?fault=SPEC][&event=NAME@SECONDS]``: a scripted fake device in-process.

Built on pySerial's ``loop://``: what the binding writes is answered by an
:class:`~opspec.bindings.emulator.EmulatedDevice` on the writing thread, and the replies are
queued for reading (late replies and events from a timer). No thread, pty or socket, so unit
tests are fast and deterministic. ``PROFILE`` is a profile file path or a profile name, looked
up in the folder of the profile it is bound with (``--devices``; ``profiles_dir``, passed by
:func:`~opspec.bindings.transport.open_port`), then in the default profile directory; ``fault`` takes the ``--fault`` forms of ``opspec devices
emulate``. A ``disconnect`` makes the next read raise ``SerialException`` while ``is_open``
stays True, exactly like an unplugged USB adapter; reopening gives a fresh device.
"""

from __future__ import annotations

import os
import threading
import urllib.parse
from typing import Any

from serial.serialutil import PortNotOpenError, SerialException
from serial.urlhandler import protocol_loop

from opspec.bindings.emulator import Behaviour, EmulatedDevice, Reply, parse_event
from opspec.bindings.profiles import DeviceProfile, resolve_profile
from opspec.errors import OpspecError

__all__ = ["Serial"]


class Serial(protocol_loop.Serial):
    """A loop:// port whose other end is an emulated device."""

    def __init__(self, *args: Any, profiles_dir: str | os.PathLike[str] | None = None,
                 **kwargs: Any) -> None:
        self.profiles_dir = profiles_dir
        self.device: EmulatedDevice | None = None
        self._vanished = False
        self._pending = b""
        self._timers: list[threading.Timer] = []
        super().__init__(*args, **kwargs)

    def from_url(self, url: str) -> None:
        rest = url.split("://", 1)[1]
        where, _, query = rest.partition("?")
        options = urllib.parse.parse_qs(query, keep_blank_values=True)
        unknown = set(options) - {"fault", "event"}
        if unknown:
            raise ValueError(f"unknown option {min(unknown)!r} in {url} "
                             "(emulator:// takes fault= and event=NAME@SECONDS)")
        try:
            profile = self._profile(urllib.parse.unquote(where))
            behaviour = Behaviour.parse(options.get("fault", ["none"])[-1])
        except OpspecError as error:
            raise SerialException(f"emulator: {error}") from None
        self.device = EmulatedDevice(profile, behaviour)
        self._vanished = False
        for spec in options.get("event", []):
            try:
                name, seconds = parse_event(spec, "event=")
            except OpspecError as error:
                raise SerialException(f"emulator: {error}") from None
            try:
                line = self.device.event_line(name)
            except OpspecError as error:
                raise SerialException(f"emulator: bad event {spec!r}: {error}") from None
            self._later(seconds, line)

    def _profile(self, name: str) -> DeviceProfile:
        """``name`` in ``profiles_dir`` when it is there (a designer's ``--devices`` folder
        holds the boards being emulated), else as :func:`resolve_profile` finds it."""
        if self.profiles_dir is None:
            return resolve_profile(name)
        try:
            return resolve_profile(name, self.profiles_dir)
        except OpspecError as there:
            try:
                return resolve_profile(name)
            except OpspecError:
                raise there from None   # the folder the designer named is the one to list

    def _later(self, delay: float, data: bytes) -> None:
        if delay <= 0:
            self._deliver(data)
            return
        timer = threading.Timer(delay, self._deliver, (data,))
        timer.daemon = True
        self._timers.append(timer)
        timer.start()

    def _deliver(self, data: bytes) -> None:
        if self.is_open and not self._vanished and self.queue is not None:
            for byte in data:
                self.queue.put(bytes((byte,)))

    def write(self, data: bytes) -> int:  # type: ignore[override]  # Buffer in 3.12
        if not self.is_open:
            raise PortNotOpenError()
        if self._vanished:
            raise SerialException("write failed: [Errno 5] Input/output error (emulated)")
        assert self.device is not None
        self._pending += bytes(data)
        newline = self.device.profile.serial.newline.encode()[-1:]
        while newline in self._pending:
            raw, self._pending = self._pending.split(newline, 1)
            line = raw.decode(self.device.profile.serial.encoding, "replace").strip()
            if not line:
                continue
            for action in self.device.handle_line(line):
                if isinstance(action, Reply):
                    self._later(action.delay_s, action.data)
                else:
                    self._vanished = True
                    if self.queue is not None:
                        self.queue.put(None)  # wake a blocked reader
        return len(data)

    def read(self, size: int = 1) -> bytes:
        if self._vanished and self.is_open:
            raise SerialException("device reports readiness to read but returned no data "
                                  "(device disconnected or multiple access on port?)")
        data = super().read(size)
        if self._vanished:
            raise SerialException("device reports readiness to read but returned no data "
                                  "(device disconnected or multiple access on port?)")
        return bytes(data)

    @property
    def in_waiting(self) -> int:
        if self._vanished:
            return 0
        return int(super().in_waiting)

    def close(self) -> None:
        for timer in self._timers:
            timer.cancel()
        super().close()
