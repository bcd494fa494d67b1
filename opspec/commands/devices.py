"""List serial ports and device profiles; emulate a device.

List serial ports and the profiles matching them, and emulate a profile's device on a
pseudo-terminal or a socket. Device profiles live in devices/ (see devices/README.md).
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
from typing import Any

from opspec.commands._args import command

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = command(subparsers, "devices", __doc__)

    def usage(_args: argparse.Namespace) -> int:      # no ACTION: the actions, status 2
        parser.print_help()
        return 2

    parser.set_defaults(handler=usage)
    sub = parser.add_subparsers(dest="devices_command", metavar="ACTION")

    listing = sub.add_parser(
        "list", help="show serial ports and which profiles match them",
        description="Show the serial ports of this machine, each with the device profiles "
        "whose port rules match it, then every profile of the folder with its participants "
        "and port rules. Virtual ports (pseudo-terminals, socket://, emulator://) are not "
        "listed: bind them by path or URL (--bind PARTICIPANT=URL).")
    listing.add_argument("--profiles", metavar="DIR", help="profile folder (default: devices/)")
    listing.set_defaults(handler=_list)

    emulate = sub.add_parser(
        "emulate", help="play a profile's device on a pseudo-terminal or a socket",
        description="Play PROFILE's device until Ctrl+C. Type an event name (e.g. report) "
        "and Enter to send that unsolicited event.")
    emulate.add_argument("profile", metavar="PROFILE", help="profile name or .toml path")
    emulate.add_argument("--port", default="pty", metavar="pty|socket://HOST:PORT",
                         help="where to listen (default: a new pseudo-terminal; "
                         "socket://127.0.0.1:0 picks a free port)")
    emulate.add_argument("--fault", default="none", metavar="SPEC",
                         help="none, silent[:N], garbage[:N], late:MS, disconnect:N, error:LINE")
    emulate.add_argument("--event", action="append", default=[], metavar="NAME@SECONDS",
                         help="send event NAME after SECONDS (repeatable), e.g. report@5")
    emulate.add_argument("--duration", type=_duration, metavar="SECONDS",
                         help="stop after SECONDS instead of waiting for Ctrl+C")
    emulate.add_argument("--quiet", action="store_true", help="do not print the traffic")
    emulate.add_argument("--profiles", metavar="DIR", help="profile folder (default: devices/)")
    emulate.set_defaults(handler=_emulate)


#: The longest --duration: a year (longer, or inf, overflows the wait; leave it out instead).
MAX_DURATION_S = 366 * 86400.0


def _duration(text: str) -> float:
    """``--duration``: seconds from 0 to :data:`MAX_DURATION_S`."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 <= value <= MAX_DURATION_S:     # nan compares false: refused too
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected seconds from 0 to {MAX_DURATION_S:,.0f} (a year); "
            "leave --duration out to emulate until Ctrl+C")
    return value


def _list(args: argparse.Namespace) -> int:
    from opspec.bindings.profiles import default_profiles_dir, load_profiles
    from opspec.bindings.transport import list_ports

    folder = args.profiles or default_profiles_dir()
    profiles = load_profiles(folder)
    ports = list_ports()
    print("Serial ports:")
    if not ports:
        print("  (none found)")
    for port in ports:
        ids = f"{port.vid:04x}:{port.pid:04x}" if port.vid is not None and port.pid else "-"
        serial_number = f" serial {port.serial_number}" if port.serial_number else ""
        matching = [p.name for p in profiles if port.matches(p.port)]
        fits = f"  -> {', '.join(matching)}" if matching else ""
        print(f"  {port.device}  [{ids}{serial_number}] {port.description}{fits}")
    print("  (virtual ports - pseudo-terminals, socket://, loop://, emulator:// - are never "
          "listed; bind them by path or URL)")
    print(f"\nProfiles in {folder}:")
    for profile in profiles:
        rules = profile.port.describe()
        print(f"  {profile.name:<22} participants: {', '.join(profile.participants):<20} "
              f"port: {rules}")
    return 0


def _emulate(args: argparse.Namespace) -> int:
    from opspec.bindings.emulator import (
        Behaviour,
        EmulatedDevice,
        PtyEmulator,
        SocketEmulator,
        parse_event,
    )
    from opspec.bindings.profiles import resolve_profile
    from opspec.errors import BindingError

    profile = resolve_profile(args.profile, args.profiles)
    device = EmulatedDevice(profile, Behaviour.parse(args.fault))
    events = [parse_event(spec) for spec in args.event]
    if args.port == "pty":
        server: PtyEmulator | SocketEmulator = PtyEmulator(device)
    elif args.port.startswith("socket://"):
        host, _, port_text = args.port[len("socket://"):].rpartition(":")
        try:
            number = int(port_text)
        except ValueError:
            raise BindingError(f"--port {args.port!r}: expected socket://HOST:PORT") from None
        if not 0 <= number <= 65535:
            raise BindingError(f"--port {args.port!r}: port {number} is not a TCP port "
                               "(0 to 65535)", hint="socket://127.0.0.1:0 picks a free port")
        server = SocketEmulator(device, host or "127.0.0.1", number)
    else:
        raise BindingError(f"--port {args.port!r}: expected pty or socket://HOST:PORT",
                           hint="the emulator creates the port; bind opspec to what it prints")
    if not args.quiet:
        server.log = lambda text: print(f"  {text}", flush=True)
    try:  # Ctrl+C at any point from here is the normal way to stop: exit 0
        for name, after in events:
            server.send_event(name, after)
        server.start()
        participants = ", ".join(profile.participants)
        print(f"Emulating {profile.name} ({participants}), fault "
              f"{device.behaviour.describe()}, on {server.url}", flush=True)
        # every participant the device serves: one left out would run simulated, unsaid
        binds = " ".join(f"--bind {p}={server.url}" for p in profile.participants)
        print(f"  bind it with: {binds}", flush=True)
        if profile.events:
            print(f"  events: {', '.join(profile.events)} (type a name and Enter to send it)",
                  flush=True)
        _read_stdin_events(server, profile.events)
        server.join(args.duration)
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    print("Emulator stopped.", flush=True)
    return 0


def _read_stdin_events(server: Any, events: Any) -> None:
    """Send the event named on each stdin line; a daemon thread, so Ctrl+C is never blocked."""
    if sys.stdin is None or sys.stdin.closed:
        return

    def loop() -> None:
        while True:
            try:
                raw = sys.stdin.readline()
            except (OSError, ValueError):  # no usable stdin (detached, captured): use --event
                return
            if not raw:  # end of input: keep emulating, stop listening
                return
            name = raw.strip()
            if name and name in events:
                server.send_event(name)
            elif name:
                print(f"  unknown event {name!r}; events: {', '.join(events) or 'none'}",
                      flush=True)

    threading.Thread(target=loop, name="emulator-stdin", daemon=True).start()
