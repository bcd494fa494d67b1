"""How the bound devices did, in words: one line per device (modes, round trips, faults) and
its faults and unfinished work, for ``opspec run`` and ``opspec walkthrough`` at the end of a
run, and when Ctrl+C stops one (the work the device had not finished then is what the
designer needs to know: a ``DISPENSE`` sent and never answered may have dropped a dose)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import TracebackType
from typing import Any

__all__ = ["FAULTS_SHOWN", "device_lines", "report_when_interrupted"]

#: faults listed per device (all are counted, and all are in the trace)
FAULTS_SHOWN = 5


def device_lines(report: Mapping[str, Mapping[str, Any]], when: str = "at the end"
                 ) -> list[str]:
    """The lines for :meth:`~opspec.bindings.attach.AttachedDevices.report`'s ``report``;
    ``when`` the unfinished work was found (``at the end``, ``when interrupted``)."""
    lines: list[str] = []
    for name, info in report.items():
        latency = info.get("latency_ms") or {}
        modes = ", ".join(f"{p} {m}" for p, m in (info.get("mode") or {}).items())
        where = info.get("url") or "simulated"
        rtt = (f"round trip mean {latency.get('mean')} ms, p99 {latency.get('p99')} ms, "
               f"max {latency.get('max')} ms over {latency.get('count')} commands"
               if latency.get("count") else "no commands answered")
        faults = info.get("faults") or []
        lines.append(f"device {name} ({info.get('profile')} on {where}): {modes}; {rtt}; "
                     f"{len(faults)} fault(s)")
        lines.extend(f"  fault {fault.get('fault')}: {fault.get('message')} "
                     f"(then {fault.get('action')})" for fault in faults[:FAULTS_SHOWN])
        if len(faults) > FAULTS_SHOWN:
            lines.append(f"  … and {len(faults) - FAULTS_SHOWN} more fault(s) (each is a "
                         "`fault` event in the trace)")
        lines.extend(f"  unfinished {when}: {waiting.get('message')}"
                     for waiting in info.get("pending") or [])
    return lines


ExitHook = Callable[[type[BaseException] | None, BaseException | None, TracebackType | None],
                    bool]


def report_when_interrupted(devices: Any, out: Any) -> ExitHook:
    """An exit hook for a :class:`contextlib.ExitStack` (``stack.push``), pushed after the
    trace is opened so it runs before the trace closes: on Ctrl+C it traces the devices'
    unfinished work (``device.pending``) and prints :func:`device_lines` to ``out``. The
    interruption goes on (exit status 130)."""
    def on_exit(kind: type[BaseException] | None, _error: BaseException | None,
                _tb: TracebackType | None) -> bool:
        if kind is not None and issubclass(kind, KeyboardInterrupt):
            for line in device_lines(devices.report(), "when interrupted"):
                print(line, file=out)
        return False
    return on_exit
