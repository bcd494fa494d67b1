"""Binding participants to devices: ``bind()`` and the ``--bind PARTICIPANT=URL`` parser.

``bind`` opens the port *before* the run: an explicit URL that cannot be opened raises a
:class:`~opspec.errors.BindingError` naming the port and the operating system's reason, so the
run stops before it begins. ``auto`` uses the profile's port rules and falls back to the
simulated device when nothing matches or the port will not open, saying so in a note (also
emitted as a ``device.note`` trace event when the binding is attached).
"""

from __future__ import annotations

import os
import time
from collections.abc import Collection, Sequence
from pathlib import Path

from opspec.bindings.binding import DeviceBinding
from opspec.bindings.inbox import Inbox
from opspec.bindings.profiles import DeviceProfile, load_profiles, profiles_serving
from opspec.bindings.transport import PortInfo, find_port, open_port, settles
from opspec.errors import BindingError

__all__ = ["AUTO", "BindSpec", "bind", "bindings_from_args", "parse_bind_spec"]

AUTO = "auto"


def bind(participants: str | Sequence[str], url: str, profile: DeviceProfile, *,
         inbox: Inbox | None = None, settle_s: float | None = None,
         ports: Sequence[PortInfo] | None = None) -> DeviceBinding:
    """Bind ``participants`` (one id or several served by the same device) to ``url``.

    ``url`` is a device path or pySerial URL, or ``"auto"``. ``settle_s`` overrides the
    profile's wait after opening (Arduino boards reset on open); by default it applies to
    plain device paths only, not to ``socket://``/``loop://``/``emulator://``. ``ports``
    replaces the operating system's port list (for tests). Raises BindingError for an
    explicit port that cannot be opened or a participant the profile does not serve.
    """
    names = (participants,) if isinstance(participants, str) else tuple(participants)
    for name in names:
        if name not in profile.participants:
            raise BindingError(
                f"profile {profile.name!r} does not serve participant {name!r}",
                hint=f"it serves: {', '.join(profile.participants)} ({profile.path})")
    label = ", ".join(names)
    if url == AUTO:
        found, how = find_port(profile, ports)
        if found is None:
            return DeviceBinding(profile, names, None, None, inbox=inbox, notes=[
                f"{label}: {how}, using the simulated {label}"])
        try:
            port = open_port(found, profile.serial, label, Path(profile.path).parent)
        except BindingError as error:
            return DeviceBinding(profile, names, None, None, inbox=inbox, notes=[
                f"{error.message}; using the simulated {label}"])
        url, notes = found, [how, f"{label}: bound to {found} ({profile.name})"]
    else:
        # emulator://NAME finds NAME beside the bound profile first (--devices DIR)
        port = open_port(url, profile.serial, label, Path(profile.path).parent)
        notes = [f"{label}: bound to {url} ({profile.name})"]
    settle = settle_s if settle_s is not None else (
        profile.serial.settle_s if settles(url) else 0.0)
    if settle > 0:
        time.sleep(settle)  # before the run: the board boots and would drop our commands
        port.reset_input_buffer()
    return DeviceBinding(profile, names, url, port, inbox=inbox, notes=notes)


class BindSpec:
    """One parsed ``PARTICIPANT[:PROFILE]=URL|auto``."""

    __slots__ = ("participant", "profile", "text", "url")

    def __init__(self, participant: str, profile: str | None, url: str, text: str) -> None:
        self.participant, self.profile, self.url, self.text = participant, profile, url, text

    def __repr__(self) -> str:
        return f"BindSpec({self.text!r})"


def parse_bind_spec(text: str) -> BindSpec:
    """Parse ``alarm=auto``, ``alarm=/dev/ttyACM0`` or ``alarm:medication_dispenser=URL``."""
    usage = ("write PARTICIPANT=URL or PARTICIPANT=auto, e.g. alarm=/dev/ttyACM0, "
             "alarm=socket://127.0.0.1:7777 or alarm:medication_dispenser=auto")
    left, sep, url = text.partition("=")
    participant, _, profile = left.partition(":")
    participant, profile, url = participant.strip(), profile.strip(), url.strip()
    if not sep or not participant or not url:
        raise BindingError(f"cannot read --bind {text!r}", hint=usage)
    if ":" in left and not profile:
        raise BindingError(f"--bind {text!r} names an empty profile after ':'", hint=usage)
    return BindSpec(participant, profile or None, url, text)


def _choose(spec: BindSpec, profiles: Sequence[DeviceProfile], folder: Path) -> DeviceProfile:
    if spec.profile is not None:
        named = [p for p in profiles if spec.profile in (p.name, Path(p.path).stem)]
        if not named:
            raise BindingError(f"--bind {spec.text!r}: no profile named {spec.profile!r} "
                               f"in {folder}",
                               hint=f"profiles: {', '.join(p.name for p in profiles) or 'none'}")
        return named[0]
    serving = profiles_serving(spec.participant, profiles)
    if not serving:
        raise BindingError(
            f"--bind {spec.text!r}: no device profile in {folder} serves participant "
            f"{spec.participant!r}",
            hint="add it to a profile's `participants`, or check the participant id in the spec")
    if len(serving) > 1:
        names = ", ".join(p.name for p in serving)
        raise BindingError(
            f"--bind {spec.text!r}: several profiles serve {spec.participant!r} ({names})",
            hint=f"pick one: {spec.participant}:{serving[0].name}={spec.url}")
    return serving[0]


def _bindable(participants: Collection[str], profiles: Sequence[DeviceProfile]) -> str:
    served = {name for profile in profiles for name in profile.participants}
    return ", ".join(sorted(name for name in participants if name in served))


def bindings_from_args(specs: Sequence[str], profiles_dir: str | os.PathLike[str], *,
                       inbox: Inbox | None = None, settle_s: float | None = None,
                       ports: Sequence[PortInfo] | None = None,
                       participants: Collection[str] | None = None) -> list[DeviceBinding]:
    """Bindings for ``--bind`` arguments, all posting into one ``inbox`` (created if None).

    ``participants``: the spec's participant ids; a ``--bind`` naming another is refused
    (with the bindable ones: the spec's participants that a profile serves), before any port
    is opened. ``None`` skips the check (no spec at hand).

    Participants bound to the same profile and the same URL share one binding (one port,
    one reader thread). Raises BindingError, before any port stays open, for a malformed
    argument, a participant bound twice, an unknown or ambiguous profile, a port claimed by
    two profiles, or an explicit port that cannot be opened.
    """
    if not specs:
        return []
    folder = Path(profiles_dir)
    profiles = load_profiles(folder)
    shared = inbox if inbox is not None else Inbox()
    groups: dict[tuple[str, str], tuple[DeviceProfile, list[str]]] = {}
    seen: dict[str, str] = {}
    for text in specs:
        spec = parse_bind_spec(text)
        if participants is not None and spec.participant not in participants:
            raise BindingError(
                f"--bind {text!r}: the spec has no participant {spec.participant!r}",
                hint=f"bindable participants of this spec: "
                f"{_bindable(participants, profiles) or 'none (no profile serves any)'}")
        if spec.participant in seen:
            raise BindingError(f"participant {spec.participant!r} is bound twice "
                               f"({seen[spec.participant]!r} and {text!r})",
                               hint="give one --bind per participant")
        seen[spec.participant] = text
        profile = _choose(spec, profiles, folder)
        if spec.participant not in profile.participants:
            raise BindingError(f"--bind {text!r}: profile {profile.name!r} does not serve "
                               f"{spec.participant!r}",
                               hint=f"it serves: {', '.join(profile.participants)}")
        groups.setdefault((profile.name, spec.url), (profile, []))[1].append(spec.participant)
    urls: dict[str, str] = {}
    for name, url in groups:
        if url != AUTO and url in urls:
            raise BindingError(f"port {url} is bound to two profiles ({urls[url]} and {name})",
                               hint="one device, one profile: bind its participants to the "
                               "same profile")
        urls[url] = name
    made: list[DeviceBinding] = []
    try:
        for (_, url), (profile, names) in groups.items():
            made.append(bind(names, url, profile, inbox=shared, settle_s=settle_s,
                             ports=ports))
    except BindingError:
        for binding in made:
            binding.close()
        raise
    return made
