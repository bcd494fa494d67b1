"""Command round-trip latency of device bindings, over a pseudo-terminal and over loop://.

    .venv/bin/python benchmarks/serial_latency.py [--commands 1000] [--json]

For each transport it sends ``ALARM ON`` N times through a DeviceBinding bound to the
medication dispenser profile (the path a run takes: the reader thread, framing, the inbox
drained on the calling thread) and reports the binding's measured round trip (command written
to reply line received) and the time from offer to completion (adds the inbox hop), as mean,
p50, p99 and max. A raw pySerial write/readline round trip is the baseline.

Transports: ``pty`` (os.openpty with the emulator on its own thread), ``emulator://`` (the
scripted fake device built on loop://, no thread on the device side) and ``loop://`` raw echo.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import serial

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from opspec.bindings import bind, load_profile, summarise
from opspec.bindings.emulator import EmulatedDevice, PtyEmulator
from opspec.bindings.latency import LatencySummary
from opspec.engine.performers import WorkItem

PROFILE = ROOT / "devices" / "medication_dispenser.toml"


class _Session:
    """The least a performer session must do: note completions."""

    now = 0.0

    def __init__(self) -> None:
        self.done = 0
        self.failures: list[str] = []

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        self.done += 1

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        self.failures.append(message)

    def omit(self, item: WorkItem, reason: str = "") -> None:
        self.failures.append(reason)

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        pass

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        callback()

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        if kind == "fault":
            self.failures.append(str(data))


def through_binding(url: str, n: int) -> tuple[LatencySummary, LatencySummary]:
    """(round trip measured by the binding, offer-to-completion) over ``url``."""
    profile = load_profile(PROFILE)
    session = _Session()
    to_completion: list[float] = []
    with bind("alarm", url, profile, settle_s=0) as binding:
        binding.attach(session)
        for key in range(n):
            work = WorkItem(key, "bench", 1, "alarm_on", "alarm_on", "alarm", "device", 0.0,
                            application="alarm_on")
            target = session.done + 1
            started = time.perf_counter()
            binding.offer(work)
            while session.done < target:
                if session.failures:
                    raise SystemExit(f"benchmark failed: {session.failures[0]}")
                binding.inbox.wait(5)
                binding.inbox.drain(session)
            to_completion.append(time.perf_counter() - started)
        return binding.latency_summary(), summarise(to_completion)


def raw_round_trip(url: str, n: int, line: bytes = b"ALARM ON\n") -> LatencySummary:
    """pySerial write + readline, no binding: the transport's own cost."""
    samples: list[float] = []
    with serial.serial_for_url(url, timeout=5) as port:
        for _ in range(n):
            started = time.perf_counter()
            port.write(line)
            reply = port.readline()
            samples.append(time.perf_counter() - started)
            if not reply:
                raise SystemExit(f"no reply from {url}")
    return summarise(samples)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--commands", type=int, default=1000)
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    n = args.commands
    results: dict[str, LatencySummary] = {}
    profile = load_profile(PROFILE)
    with PtyEmulator(EmulatedDevice(profile)) as emulator:
        results["pty raw write/readline"] = raw_round_trip(emulator.url, n)
        results["pty binding round trip"], results["pty binding offer->complete"] = \
            through_binding(emulator.url, n)
    url = f"emulator://{PROFILE}"
    results["emulator:// raw write/readline"] = raw_round_trip(url, n)
    results["emulator:// binding round trip"], results["emulator:// binding offer->complete"] \
        = through_binding(url, n)
    results["loop:// raw echo"] = raw_round_trip("loop://", n)
    if args.json:
        print(json.dumps({k: {"count": v.count, "mean": v.mean, "p50": v.p50, "p99": v.p99,
                              "max": v.max} for k, v in results.items()}, indent=2))
        return 0
    print(f"Command round trip, {n} commands each (milliseconds)")
    print(f"{'':38}{'mean':>9}{'p50':>9}{'p99':>9}{'max':>9}")
    for name, s in results.items():
        print(f"{name:38}{s.mean * 1e3:9.3f}{s.p50 * 1e3:9.3f}{s.p99 * 1e3:9.3f}"
              f"{s.max * 1e3:9.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
