"""The shipped dispenser spec and profile, end to end, against an independent board process
(tests/bindings/dispenser_board.py, which imports nothing from opspec) over a real
pseudo-terminal pair made by socat: a clean run, garbage, late replies, a jammed drawer, an
empty slot, an unplugged cable and a press before any alarm. In every case each due dose
ends as taken or missed (taken + missed = due), and a device fault reaches the caregiver.

Each run goes from 00:00 to 11:40 simulated at 5000x (about 9 s of wall time plus the
profile's 2 s settle after opening the port): one dose, at 08:00, slot 1.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main

from .conftest import needs_pty

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
BOARD = Path(__file__).with_name("dispenser_board.py")
RUN = ["--until", "42000", "--realtime", "--speed", "5000", "--no-user"]

pytestmark = [
    needs_pty,
    pytest.mark.skipif(shutil.which("socat") is None,
                       reason="needs socat for the pty pair: run scripts/system-deps.sh"),
]


class Rig:
    """A socat pty pair (host end for opspec, board end for the board process)."""

    def __init__(self, folder: Path) -> None:
        self.host = folder / "host"
        self.board_end = folder / "board"
        self.socat = subprocess.Popen(
            ["socat", f"pty,link={self.host},raw,echo=0",
             f"pty,link={self.board_end},raw,echo=0"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 5
        while not (self.host.exists() and self.board_end.exists()):
            if time.monotonic() > deadline or self.socat.poll() is not None:
                raise RuntimeError("socat did not make the pty pair")
            time.sleep(0.02)
        self.board: subprocess.Popen[str] | None = None

    def start_board(self, *options: str) -> None:
        self.board = subprocess.Popen(
            [sys.executable, str(BOARD), str(self.board_end), "--socat-pid",
             str(self.socat.pid), *options], stdout=subprocess.PIPE, text=True)
        assert self.board.stdout is not None
        assert self.board.stdout.readline().strip() == "READY"

    def board_log(self) -> list[str]:
        assert self.board is not None
        if self.board.poll() is None:
            self.board.terminate()
        out, _ = self.board.communicate(timeout=5)
        return out.splitlines()

    def stop(self) -> None:
        for proc in (self.board, self.socat):
            if proc is not None and proc.poll() is None:
                proc.terminate()
                proc.wait(timeout=5)


@pytest.fixture
def rig(tmp_path: Path) -> Iterator[Rig]:
    made = Rig(tmp_path)
    try:
        yield made
    finally:
        made.stop()


def run(rig: Rig, capsys: pytest.CaptureFixture[str], tmp_path: Path,
        *options: str, engine: str = "") -> tuple[int, dict[str, Any], list[dict[str, Any]],
                                                  list[str]]:
    """Start the board with ``options``, run the spec bound to it (``engine``: engine
    configuration TOML); the exit status, the JSON document, the trace and the board's log."""
    rig.start_board(*options)
    trace = tmp_path / "trace.jsonl"
    extra: list[str] = []
    if engine:
        config = tmp_path / "engine.toml"
        config.write_text(engine, encoding="utf-8")
        extra = ["--engine-config", str(config)]
    status = main(["run", str(SPEC), *RUN, *extra, "--json", "--trace", str(trace),
                   "--bind", f"alarm={rig.host}", "--bind", f"dispenser={rig.host}"])
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    events = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    return status, doc, events, rig.board_log()


def totals(doc: dict[str, Any]) -> dict[str, int]:
    return {name: doc["metrics"][name]["total"] for name in
            ("doses_due", "doses_taken", "doses_missed", "caregiver_notified")}


def device(doc: dict[str, Any]) -> dict[str, Any]:
    return doc["devices"]["alarm, dispenser"]


def fault_kinds(doc: dict[str, Any]) -> list[str]:
    return [f["fault"] for f in device(doc)["faults"]]


def completed(events: list[dict[str, Any]], activity: str) -> list[dict[str, Any]]:
    return [e for e in events if e.get("kind") == "activity.completed"
            and e.get("activity") == activity]


def assert_every_dose_decided(doc: dict[str, Any], events: list[dict[str, Any]]) -> None:
    counts = totals(doc)
    assert counts["doses_due"] == 1
    assert counts["doses_taken"] + counts["doses_missed"] == counts["doses_due"], counts
    ended = [e for e in events if e.get("kind") == "process.completed"
             and e.get("process") == "notify_workflow"]
    assert len(ended) == counts["doses_due"], "a notify instance did not end"
    assert not [e for e in events if e.get("kind") == "process.aborted"
                and e.get("process") != "user_workflow"]
    # --no-user: the board's button reports, nobody performs the user lane, whose instances
    # are the only ones left waiting (reported as deadlocks, hence exit status 1)
    assert all("'user_workflow'" in d for d in doc.get("deadlocks") or []), doc["deadlocks"]


def test_clean_board_the_morning_dose_is_taken_from_slot_1(rig, capsys, tmp_path):
    _, doc, events, log = run(rig, capsys, tmp_path)
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    assert "RX DISPENSE 1" in log                   # the morning dose's slot, not "DISPENSE 1"
    assert fault_kinds(doc) == []                   # by default for every dose
    assert device(doc)["mode"] == {"alarm": "device", "dispenser": "device"}


def test_garbage_is_a_fault_then_a_retry_and_the_dose_is_taken(rig, capsys, tmp_path):
    # the garbled answer ends its attempt at the 500 ms timeout (a reply may follow noise),
    # over an hour simulated at 5000x: the press 20 ms after the first ALARM ON is kept
    # for the dose's wait (as in the late-reply test below)
    _, doc, events, log = run(rig, capsys, tmp_path, "--garbage", "1", "--noise",
                              engine="message_ttl = 86400\n")
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    kinds = fault_kinds(doc)
    assert "garbage" in kinds and "unexpected-line" in kinds
    assert log.count("RX ALARM ON") == 2            # the garbled answer was retried once
    assert device(doc)["mode"]["alarm"] == "device"


def test_a_late_reply_and_a_press_during_the_retry_the_press_is_not_lost(
        rig, capsys, tmp_path):
    # ALARM ON's reply comes 800 ms late (timeout 500 ms): timeout, late-reply, retry. The
    # user presses 20 ms after the first ALARM ON, while nothing waits for the report yet:
    # the message is kept and the dose's wait catches it. (At this test's 5000x speed the
    # retry's wall-clock second is over an hour of simulated time: longer than the default
    # message_ttl of 60 s, so the test keeps messages for a day.)
    _, doc, events, log = run(rig, capsys, tmp_path, "--late-ms", "800",
                              "--late-count", "1", engine="message_ttl = 86400\n")
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    kinds = fault_kinds(doc)
    assert kinds[:2] == ["timeout", "late-reply"], kinds
    assert [e for e in events if e.get("kind") == "trigger.kept"]
    assert log.count("RX ALARM ON") == 2
    assert device(doc)["mode"]["alarm"] == "device"  # one failed attempt does not switch


def test_a_jammed_drawer_is_a_missed_dose_and_the_caregiver_is_told(rig, capsys, tmp_path):
    _, doc, events, log = run(rig, capsys, tmp_path, "--jam")
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == 1
    assert totals(doc)["caregiver_notified"] == 1
    assert completed(events, "drawer_jammed")
    assert [f for f in device(doc)["faults"] if f["fault"] == "device-error"]
    assert "RX DISPENSE 1" in log


def test_an_empty_slot_is_a_missed_dose_and_the_caregiver_is_told(rig, capsys, tmp_path):
    _, doc, events, _ = run(rig, capsys, tmp_path, "--empty")
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == totals(doc)["caregiver_notified"] == 1
    assert completed(events, "drawer_empty")
    assert "device-error" in fault_kinds(doc)


def test_an_unplugged_cable_at_dispense_is_a_missed_dose_and_the_caregiver_is_told(
        rig, capsys, tmp_path):
    _, doc, events, log = run(rig, capsys, tmp_path, "--unplug-on", "DISPENSE")
    assert "UNPLUG" in log
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == totals(doc)["caregiver_notified"] == 1
    assert completed(events, "dispense_failed")
    kinds = fault_kinds(doc)
    assert "disconnected" in kinds and "reconnect-failed" in kinds
    assert device(doc)["mode"] == {"alarm": "simulated", "dispenser": "aborted"}


def test_a_press_long_before_the_alarm_is_lost_and_does_not_report_the_next_dose(
        rig, capsys, tmp_path):
    # documented in devices/README.md: the board's presses are plain messages; one with
    # nothing waiting is kept for message_ttl (60 s) and then lost, so a press hours before
    # the 08:00 alarm does not count as taking that dose (here nobody presses again: missed)
    _, doc, events, _ = run(rig, capsys, tmp_path, "--press-at-ms", "3500", "--no-press")
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 0 and totals(doc)["doses_missed"] == 1
    kept = [e for e in events if e.get("kind") == "trigger.kept"]
    lost = [e for e in events if e.get("kind") == "trigger.lost"]
    assert kept and kept[0]["time"] < 8 * 3600
    assert lost and "message_ttl" in lost[0]["data"]["reason"]
