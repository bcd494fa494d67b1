"""Device profiles: TOML files in ``devices/`` that say how a serial device performs work.

A profile names the participants it serves, how to find its port, the serial settings, the
line protocol (commands per operation, replies, errors, unsolicited events) and the fallback
when the device misbehaves. The format is documented in ``devices/README.md``; this module
turns a file into a frozen :class:`DeviceProfile` or raises a
:class:`~opspec.errors.BindingError` that names the file and the dotted key at fault.

Profiles are plain data: nothing here opens a port or imports pyserial.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Final, Literal

from opspec.bindings.templates import LineTemplate, TemplateError
from opspec.errors import BindingError, SourceLocation

__all__ = [
    "PROFILE_FORMAT",
    "DeviceProfile",
    "EventRule",
    "Fallback",
    "Operation",
    "PortMatch",
    "SerialSettings",
    "default_profiles_dir",
    "load_profile",
    "load_profiles",
    "profiles_serving",
    "resolve_profile",
]

PROFILE_FORMAT: Final = 1
FallbackAction = Literal["simulate", "abort"]
FallbackScope = Literal["run", "command"]
_PARITIES: Final = {"none": "N", "even": "E", "odd": "O", "mark": "M", "space": "S"}
_VID_PID: Final = re.compile(r"([0-9A-Fa-f]{4}):([0-9A-Fa-f]{4})\Z")
_EMPTY: Final[Mapping[str, Any]] = MappingProxyType({})
# the longest times a profile may give: a command timeout, settle wait or reconnection delay
# beyond an hour (a simulated operation beyond a day) is a typo, and threading.Timer and
# time.sleep overflow on 1e300 (inf and nan are valid TOML floats)
_MAX_MILLIS: Final = 3_600_000.0
_MAX_SECONDS: Final = 86_400.0


def _empty() -> Mapping[str, Any]:
    return _EMPTY


@dataclass(frozen=True, slots=True)
class PortMatch:
    """How ``auto`` finds the port: an explicit ``url``, or rules matched against
    ``serial.tools.list_ports.comports()`` (all given rules must hold)."""

    url: str | None = None
    vid: int | None = None
    pid: int | None = None
    serial_number: str | None = None
    description: str | None = None

    @property
    def has_rules(self) -> bool:
        return any(v is not None for v in (self.vid, self.serial_number, self.description))

    def describe(self) -> str:
        """The rules in words, for notes such as "no device matched VID:PID 2341:0043"."""
        words: list[str] = []
        if self.vid is not None and self.pid is not None:
            words.append(f"VID:PID {self.vid:04x}:{self.pid:04x}")
        if self.serial_number is not None:
            words.append(f"serial number {self.serial_number!r}")
        if self.description is not None:
            words.append(f"description containing {self.description!r}")
        if self.url is not None:
            words.append(f"port {self.url}")
        return ", ".join(words) or "no port rules"

    def matches(self, vid: int | None, pid: int | None, serial_number: str | None,
                description: str | None) -> bool:
        """Whether a listed port (its USB ids, serial number, description) fits every rule."""
        if not self.has_rules:
            return False
        if self.vid is not None and (vid, pid) != (self.vid, self.pid):
            return False
        if self.serial_number is not None and serial_number != self.serial_number:
            return False
        return self.description is None or (
            self.description.lower() in (description or "").lower())


@dataclass(frozen=True, slots=True)
class SerialSettings:
    """Serial line settings and framing. Times are seconds (the TOML file uses ms)."""

    baudrate: int = 115200
    bytesize: int = 8
    parity: str = "N"
    stopbits: float = 1
    newline: str = "\n"
    encoding: str = "ascii"
    settle_s: float = 0.0
    reply_timeout_s: float = 0.5
    max_line_bytes: int = 256


@dataclass(frozen=True, slots=True)
class Operation:
    """What the device does for one application (or activity) id.

    ``command`` is ``None`` for a *passive* operation: nothing is sent, the offered activity
    waits (without a reply timeout) for an event whose ``complete`` names it.
    """

    name: str
    command: LineTemplate | None
    ok: tuple[LineTemplate, ...]
    errors: tuple[tuple[LineTemplate, str], ...]
    timeout_s: float
    defaults: Mapping[str, Any] = field(default_factory=_empty)
    simulate_duration_s: float = 0.0
    simulate_data: Mapping[str, Any] = field(default_factory=_empty)
    emulate_reply: LineTemplate | None = None
    emulate_values: Mapping[str, Any] = field(default_factory=_empty)


@dataclass(frozen=True, slots=True)
class EventRule:
    """An unsolicited line and what it does: complete an offered activity whose application
    or activity id is ``complete``, raise message trigger ``trigger``, or both (the activity
    first). Placeholder values become the trigger's / completion's data."""

    name: str
    line: LineTemplate
    trigger: str | None = None
    complete: str | None = None
    emulate_values: Mapping[str, Any] = field(default_factory=_empty)


@dataclass(frozen=True, slots=True)
class Fallback:
    """What a participant's binding does when the device fails it.

    ``retries`` resends after a timeout, garbage or a disconnect (after reconnecting);
    ``reconnect_attempts`` reopen tries after a disconnect, ``reconnect_delay_s`` apart;
    when that is exhausted, ``then``: ``simulate`` (the participant continues on the
    simulated device) or ``abort`` (the activity fails with ``exception``, following its
    EXCEPTION transition; later activities fail the same way).

    ``scope``: how long ``then`` lasts when a command runs out of retries on a port that is
    still open (timeouts, garbage): ``run`` (the participant stays simulated for the rest of
    the run) or ``command`` (only that command is simulated or failed; the next one goes to
    the device again). A port that could not be reopened is gone for the rest of the run
    whatever the scope.

    ``late_reply_s``: after a timeout the line is held this long (``None``: the command's own
    timeout) before anything else is sent, so that a late reply is reported as the timed-out
    command's ``late-reply`` instead of being taken as the answer to the retry or to the next
    command (line protocols carry no sequence numbers). A late reply ends the hold early.
    """

    retries: int = 1
    reconnect_attempts: int = 2
    reconnect_delay_s: float = 0.2
    then: FallbackAction = "simulate"
    exception: str = "DeviceFault"
    late_reply_s: float | None = None
    scope: FallbackScope = "run"


@dataclass(frozen=True, slots=True)
class DeviceProfile:
    """One device's profile, loaded from ``path``."""

    name: str
    path: str
    description: str
    participants: tuple[str, ...]
    port: PortMatch
    serial: SerialSettings
    operations: Mapping[str, Operation]
    events: Mapping[str, EventRule] = field(default_factory=_empty)
    ignore: tuple[LineTemplate, ...] = ()
    fallback: Fallback = field(default_factory=Fallback)
    participant_fallbacks: Mapping[str, Fallback] = field(default_factory=_empty)
    emulator_unknown_reply: str = "ERR UNKNOWN"

    def fallback_for(self, participant: str | None) -> Fallback:
        """The fallback declared for ``participant``, else the profile's default."""
        return self.participant_fallbacks.get(participant or "", self.fallback)

    def operation_for(self, application: str | None, activity: str) -> Operation | None:
        """The operation for a work item: by application id first, then by activity id."""
        if application is not None and application in self.operations:
            return self.operations[application]
        return self.operations.get(activity)


# --------------------------------------------------------------------------- loading

_MISSING: Final = object()


class _Table:
    """A TOML table being read: typed getters that raise BindingError naming file and key,
    and a final check that rejects unknown keys (typos must not pass silently)."""

    def __init__(self, path: str, data: Mapping[str, Any], prefix: str = "") -> None:
        self.path, self.data, self.prefix = path, data, prefix
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def error(self, name: str, message: str, hint: str = "") -> BindingError:
        location = SourceLocation(self.path, key=self.key(name) if name else self.prefix or None)
        return BindingError(message, location=location,
                            hint=hint or "see devices/README.md for the profile format")

    def raw(self, name: str, default: Any = _MISSING) -> Any:
        self.used.add(name)
        if name in self.data:
            return self.data[name]
        if default is _MISSING:
            raise self.error(name, "required key is missing")
        return default

    def typed(self, name: str, kinds: type | tuple[type, ...], what: str,
              default: Any = _MISSING) -> Any:
        if name not in self.data and default is not _MISSING:
            self.used.add(name)
            return default
        value = self.raw(name)
        # bool is an int in Python, never in a profile
        if isinstance(value, bool) and bool not in (kinds if isinstance(kinds, tuple) else (kinds,)):
            raise self.error(name, f"expected {what}, got {value!r}")
        if not isinstance(value, kinds):
            raise self.error(name, f"expected {what}, got {value!r}")
        return value

    def string(self, name: str, default: Any = _MISSING) -> Any:
        return self.typed(name, str, "a string", default)

    def integer(self, name: str, default: Any = _MISSING, minimum: int = 0) -> Any:
        value = self.typed(name, int, "an integer", default)
        if value is not None and value < minimum:
            raise self.error(name, f"expected an integer >= {minimum}, got {value}")
        return value

    def millis(self, name: str, default_s: float) -> float:
        value = self.typed(name, (int, float), "a number of milliseconds", None)
        if value is None:
            return default_s
        self.check_finite(name, value, "ms", _MAX_MILLIS)
        return float(value) / 1000.0

    def seconds(self, name: str, default_s: float) -> float:
        value = self.typed(name, (int, float), "a number of seconds", None)
        if value is None:
            return default_s
        self.check_finite(name, value, "s", _MAX_SECONDS)
        return float(value)

    def check_finite(self, name: str, value: float, unit: str, maximum: float) -> None:
        """TOML has ``inf`` and ``nan``: neither is a time a timer or sleep can take."""
        if math.isnan(value) or not 0 <= value <= maximum:
            raise self.error(name, f"expected a duration >= 0 {unit} and at most "
                             f"{maximum:g} {unit}, got {value}",
                             hint="write a plain number (not inf or nan), e.g. 500")

    def template(self, name: str, default: Any = _MISSING) -> Any:
        if name not in self.data and default is not _MISSING:
            self.used.add(name)
            return default
        return self.parse_template(name, self.string(name))

    def parse_template(self, name: str, text: str) -> LineTemplate:
        try:
            return LineTemplate.parse(text)
        except TemplateError as error:
            raise self.error(name, str(error)) from None

    def templates(self, name: str) -> tuple[LineTemplate, ...] | None:
        value = self.raw(name, None)
        if value is None:
            return None
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.error(name, f"expected a string or a list of strings, got {value!r}")
        return tuple(self.parse_template(name, v) for v in value)

    def table(self, name: str, required: bool = False) -> _Table:
        value = self.raw(name, _MISSING if required else {})
        if not isinstance(value, dict):
            raise self.error(name, f"expected a table ([{self.key(name)}]), got {value!r}")
        return _Table(self.path, value, self.key(name))

    def scalars(self, name: str) -> Mapping[str, Any]:
        """A table of plain values (defaults, simulated results, emulator values)."""
        sub = self.table(name)
        for key, value in sub.data.items():
            if isinstance(value, (dict, list)):
                raise sub.error(key, f"expected a string, number or boolean, got {value!r}")
        return MappingProxyType(dict(sub.data))

    def finish(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            known = ", ".join(sorted(self.used)) or "none"
            raise self.error(unknown[0], "unknown key", hint=f"known keys here: {known}; "
                             "see devices/README.md")


def load_profile(path: str | os.PathLike[str]) -> DeviceProfile:
    """Read and validate one profile file; raise BindingError naming file and key."""
    from opspec.bindings.profile_lines import located
    from opspec.toml_files import read_toml

    where = str(path)
    try:
        data = read_toml(path, what=f"device profile {where}", error=BindingError,
                         syntax_hint="fix the syntax; see devices/README.md", missing=(
                             f"device profile {where} does not exist",
                             "profiles live in devices/; see `opspec devices list`"))
        return _build(where, data)
    except BindingError as error:
        raise located(error, where) from None


def _build(path: str, data: Mapping[str, Any]) -> DeviceProfile:
    top = _Table(path, data)
    version = top.integer("format")
    if version != PROFILE_FORMAT:
        raise top.error("format", f"unsupported profile format {version}",
                        hint=f"this opspec reads format {PROFILE_FORMAT}")
    name = top.string("name", Path(path).stem)
    description = top.string("description", "")
    participants = top.raw("participants")
    if (not isinstance(participants, list) or not participants
            or not all(isinstance(p, str) and p for p in participants)):
        raise top.error("participants", f"expected a non-empty list of participant ids, "
                        f"got {participants!r}")
    if len(set(participants)) != len(participants):
        raise top.error("participants", "a participant is listed twice")

    port = _port(top.table("port"))
    serial = _serial(top.table("serial"))
    replies = top.table("replies")
    default_ok = replies.templates("ok") or (LineTemplate.parse("OK"),)
    ignore = replies.templates("ignore") or ()
    replies.finish()
    errors = _errors(top.table("errors"))

    operations_table = top.table("operations", required=True)
    if not operations_table.data:
        raise top.error("operations", "a profile needs at least one operation",
                        hint="add [operations.<application id>] with a command")
    operations = {
        op_name: _operation(operations_table.table(op_name), op_name, default_ok, errors,
                            serial.reply_timeout_s)
        for op_name in operations_table.data
    }
    events_table = top.table("events")
    events = {ev_name: _event(events_table.table(ev_name), ev_name)
              for ev_name in events_table.data}
    fallback, per_participant = _fallbacks(top.table("fallback"), participants)
    emulator = top.table("emulator")
    unknown_reply = emulator.string("unknown_reply", "ERR UNKNOWN")
    emulator.finish()
    top.finish()
    return DeviceProfile(
        name=name, path=path, description=description, participants=tuple(participants),
        port=port, serial=serial, operations=MappingProxyType(operations),
        events=MappingProxyType(events), ignore=ignore, fallback=fallback,
        participant_fallbacks=MappingProxyType(per_participant),
        emulator_unknown_reply=unknown_reply,
    )


def _port(table: _Table) -> PortMatch:
    url = table.string("url", None)
    vid = pid = None
    vid_pid = table.string("vid_pid", None)
    if vid_pid is not None:
        found = _VID_PID.match(vid_pid)
        if found is None:
            raise table.error("vid_pid", f"expected four hex digits, a colon and four hex "
                              f"digits (like \"2341:0043\"), got {vid_pid!r}")
        vid, pid = int(found.group(1), 16), int(found.group(2), 16)
    serial_number = table.string("serial_number", None)
    description = table.string("description", None)
    table.finish()
    return PortMatch(url, vid, pid, serial_number, description)


def _serial(table: _Table) -> SerialSettings:
    baudrate = table.integer("baudrate", 115200, minimum=1)
    bytesize = table.integer("bytesize", 8)
    if bytesize not in (5, 6, 7, 8):
        raise table.error("bytesize", f"expected 5, 6, 7 or 8, got {bytesize}")
    parity = table.string("parity", "none")
    if parity not in _PARITIES:
        raise table.error("parity", f"expected one of {', '.join(_PARITIES)}, got {parity!r}")
    stopbits = table.typed("stopbits", (int, float), "1, 1.5 or 2", 1)
    if stopbits not in (1, 1.5, 2):
        raise table.error("stopbits", f"expected 1, 1.5 or 2, got {stopbits}")
    newline = table.string("newline", "\n")
    if newline not in ("\n", "\r\n", "\r"):
        raise table.error("newline", f"expected \"\\n\", \"\\r\\n\" or \"\\r\", got {newline!r}")
    encoding = table.string("encoding", "ascii")
    try:
        "".encode(encoding)
    except LookupError:
        raise table.error("encoding", f"unknown encoding {encoding!r}") from None
    settings = SerialSettings(
        baudrate=baudrate, bytesize=bytesize, parity=_PARITIES[parity],
        stopbits=float(stopbits) if stopbits == 1.5 else int(stopbits), newline=newline,
        encoding=encoding, settle_s=table.millis("settle_ms", 0.0),
        reply_timeout_s=table.millis("reply_timeout_ms", 0.5),
        max_line_bytes=table.integer("max_line_bytes", 256, minimum=16),
    )
    table.finish()
    return settings


def _errors(table: _Table) -> tuple[tuple[LineTemplate, str], ...]:
    rules: list[tuple[LineTemplate, str]] = []
    for pattern in table.data:
        exception = table.string(pattern)
        if not exception.isidentifier():
            raise table.error(pattern, f"the exception name must be an identifier (it names "
                              f"an EXCEPTION transition), got {exception!r}")
        rules.append((table.parse_template(pattern, pattern), exception))
    table.finish()
    return tuple(rules)


def _operation(table: _Table, name: str, default_ok: tuple[LineTemplate, ...],
               profile_errors: tuple[tuple[LineTemplate, str], ...],
               default_timeout: float) -> Operation:
    command = table.template("command", None)
    ok = table.templates("ok") or default_ok
    errors = _errors(table.table("errors")) + profile_errors
    timeout = table.millis("timeout_ms", default_timeout)
    defaults = table.scalars("defaults")
    simulate = table.table("simulate")
    duration = simulate.seconds("duration_s", 0.0)
    sim_data = simulate.scalars("data")
    simulate.finish()
    emulate = table.table("emulate")
    reply = emulate.template("reply", None)
    values = {k: v for k, v in emulate.data.items() if k != "reply"}
    emulate.used.update(values)
    table.finish()
    return Operation(name, command, ok, errors, timeout, defaults, duration, sim_data, reply,
                     MappingProxyType(values))


def _event(table: _Table, name: str) -> EventRule:
    line = table.template("line")
    trigger = table.string("trigger", None)
    complete = table.string("complete", None)
    if trigger is None and complete is None:
        raise table.error("", "an event needs `trigger` (a message trigger to raise), "
                          "`complete` (an application/activity id to complete), or both")
    values = table.scalars("emulate")
    table.finish()
    return EventRule(name, line, trigger, complete, values)


def _one_fallback(table: _Table, base: Fallback) -> Fallback:
    then = table.string("then", base.then)
    if then not in ("simulate", "abort"):
        raise table.error("then", f"expected \"simulate\" or \"abort\", got {then!r}")
    scope = table.string("scope", base.scope)
    if scope not in ("run", "command"):
        raise table.error("scope", f"expected \"run\" or \"command\", got {scope!r}")
    exception = table.string("exception", base.exception)
    if not exception.isidentifier():
        raise table.error("exception", f"expected an exception name (an identifier), "
                          f"got {exception!r}")
    return Fallback(
        retries=table.integer("retries", base.retries),
        reconnect_attempts=table.integer("reconnect_attempts", base.reconnect_attempts),
        reconnect_delay_s=table.millis("reconnect_delay_ms", base.reconnect_delay_s),
        then=then, exception=exception, scope=scope,
        late_reply_s=(table.millis("late_reply_ms", 0.0) if "late_reply_ms" in table.data
                      else base.late_reply_s),
    )


def _fallbacks(table: _Table, participants: list[str]) -> tuple[Fallback, dict[str, Fallback]]:
    scalar_keys = {k: v for k, v in table.data.items() if not isinstance(v, dict)}
    scalars = _Table(table.path, scalar_keys, table.prefix)
    default = _one_fallback(scalars, Fallback())
    scalars.finish()
    per: dict[str, Fallback] = {}
    for key, value in table.data.items():
        if not isinstance(value, dict):
            continue
        if key not in participants:
            raise table.error(key, f"[fallback.{key}] names no participant of this profile",
                              hint=f"participants: {', '.join(participants)}")
        sub = table.table(key)
        per[key] = _one_fallback(sub, default)
        sub.finish()
    return default, per


# --------------------------------------------------------------------------- directories

def default_profiles_dir() -> Path:
    """``$OPSPEC_DEVICES``, else ``./devices`` if it exists, else the source tree's ``devices``."""
    env = os.environ.get("OPSPEC_DEVICES")
    if env:
        return Path(env)
    here = Path.cwd() / "devices"
    if here.is_dir():
        return here
    return Path(__file__).resolve().parents[2] / "devices"


def load_profiles(directory: str | os.PathLike[str]) -> list[DeviceProfile]:
    """Every ``*.toml`` profile in ``directory``, sorted by name; duplicate names raise."""
    folder = Path(directory)
    if not folder.is_dir():
        from opspec.files import not_a_file

        why = not_a_file(folder)
        kind = ("a regular file" if why is None
                else why.removeprefix("it is ").removesuffix(", not a regular file"))
        what = "does not exist" if why == "it does not exist" else f"is {kind}, not a folder"
        raise BindingError(f"device profile directory {folder} {what}",
                           hint="pass the folder holding the *.toml device profiles")
    profiles = [load_profile(p) for p in sorted(folder.glob("*.toml"))]
    seen: dict[str, str] = {}
    for profile in profiles:
        if profile.name in seen:
            raise BindingError(f"two profiles are named {profile.name!r}: {seen[profile.name]} "
                               f"and {profile.path}", location=SourceLocation(profile.path, key="name"),
                               hint="give each profile a unique `name`")
        seen[profile.name] = profile.path
    return sorted(profiles, key=lambda p: p.name)


def profiles_serving(participant: str, profiles: Iterable[DeviceProfile]) -> list[DeviceProfile]:
    """The profiles that list ``participant``."""
    return [p for p in profiles if participant in p.participants]


def resolve_profile(name_or_path: str, directory: str | os.PathLike[str] | None = None
                    ) -> DeviceProfile:
    """A profile given as a file path, or by name (or file stem) within ``directory``."""
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.is_file():
        return load_profile(candidate)
    folder = Path(directory) if directory is not None else default_profiles_dir()
    profiles = load_profiles(folder)
    for profile in profiles:
        if name_or_path in (profile.name, Path(profile.path).stem):
            return profile
    names = ", ".join(p.name for p in profiles) or "none"
    raise BindingError(f"no device profile named {name_or_path!r} in {folder}",
                       hint=f"available: {names}")
