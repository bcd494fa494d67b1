"""Device bindings: participants performed by serial devices (hardware in the loop).

Profiles (:mod:`~opspec.bindings.profiles`) describe devices; :func:`bind` and
:func:`bindings_from_args` open ports and return :class:`DeviceBinding` performers, which
answer the engine through an :class:`Inbox` drained on the engine's thread; emulators
(:mod:`~opspec.bindings.emulator`) play a profile's device on a pty, a socket or
``emulator://``. This package imports pySerial; nothing below :mod:`opspec.bindings` does.
"""

from opspec.bindings.bind import AUTO, bind, bindings_from_args, parse_bind_spec
from opspec.bindings.binding import DEVICE_EVENT, DEVICE_EXCHANGE, DEVICE_NOTE, DeviceBinding
from opspec.bindings.inbox import Inbox
from opspec.bindings.latency import LatencySummary, summarise
from opspec.bindings.profiles import (
    DeviceProfile,
    default_profiles_dir,
    load_profile,
    load_profiles,
    resolve_profile,
)

__all__ = [
    "AUTO",
    "DEVICE_EVENT",
    "DEVICE_EXCHANGE",
    "DEVICE_NOTE",
    "DeviceBinding",
    "DeviceProfile",
    "Inbox",
    "LatencySummary",
    "bind",
    "bindings_from_args",
    "default_profiles_dir",
    "load_profile",
    "load_profiles",
    "parse_bind_spec",
    "resolve_profile",
    "summarise",
]
