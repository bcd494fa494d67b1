"""The device lines after a run (`opspec run --bind`, `opspec walkthrough --bind`): the
first faults, and how many more there were, instead of leaving them out unsaid."""

from __future__ import annotations

from opspec.commands.devices_summary import FAULTS_SHOWN, device_lines


def _report(faults: int) -> dict:
    return {"motors": {
        "profile": "cart_motors", "url": "socket://127.0.0.1:7011",
        "mode": {"motors": "aborted"},
        "latency_ms": {"count": 0, "mean": None, "p99": None, "max": None},
        "faults": [{"fault": "unavailable", "message": f"motors: unavailable #{n}",
                    "action": "abort"} for n in range(faults)],
        "pending": []}}


def test_faults_beyond_the_first_are_counted() -> None:
    lines = device_lines(_report(54))
    assert lines[0].endswith("no commands answered; 54 fault(s)")
    assert len([line for line in lines if line.startswith("  fault ")]) == FAULTS_SHOWN
    assert lines[-1] == ("  … and 49 more fault(s) (each is a `fault` event in the trace)")


def test_no_more_line_when_all_are_shown() -> None:
    lines = device_lines(_report(FAULTS_SHOWN))
    assert not any("more fault" in line for line in lines)
