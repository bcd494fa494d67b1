"""The shipped dispenser spec and profile against the independent board process
(dispenser_board.py, which imports nothing from opspec) over real pseudo-terminal pairs made by
socat: one `opspec run` per board behaviour, all of them at once.

Each run goes from 00:00 to 11:40 simulated at 5000x (about 8.4 s of wall time; a
pseudo-terminal is not waited for as a board that resets when opened is): one dose, at 08:00,
slot 1. A run spends that
time waiting on the wall clock, so the runs go side by side, each in a process of its own with
a socat pair and a board of its own (nothing is shared but the machine): all of them take the
wall time of one, where one after another they held a test worker idle for 10 s each. The
session fixture ``board_runs`` (conftest.py) makes them once, the first time a test asks.
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
BOARD = Path(__file__).with_name("dispenser_board.py")
RUN = ["--until", "42000", "--realtime", "--speed", "5000", "--no-user"]

#: keeps a message a simulated day: at 5000x a retry's wall-clock second is over an hour of
#: simulated time, longer than the default message_ttl of 60 s
KEEP_A_DAY = "message_ttl = 86400\n"

#: name -> (the board's options, engine configuration TOML or "")
SCENARIOS: dict[str, tuple[tuple[str, ...], str]] = {
    "early-press": (("--press-at-ms", "3500", "--no-press"), ""),
    "clean": ((), ""),
    "garbage": (("--garbage", "1", "--noise"), KEEP_A_DAY),
    "late-reply": (("--late-ms", "800", "--late-count", "1"), KEEP_A_DAY),
    "jam": (("--jam",), ""),
    "empty": (("--empty",), ""),
    "unplug": (("--unplug-on", "DISPENSE"), ""),
    "noise-before": (("--noise-before",), ""),
}


@dataclass(frozen=True)
class BoardRun:
    """What one run left: `opspec run`'s exit status, its JSON document, its trace, the
    board's log (``RX <command>`` per command received) and the run's stderr."""

    status: int
    doc: dict[str, Any]
    events: list[dict[str, Any]]
    log: list[str]
    stderr: str


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


def _command(folder: Path, host: Path, engine: str) -> list[str]:
    extra: list[str] = []
    if engine:
        config = folder / "engine.toml"
        config.write_text(engine, encoding="utf-8")
        extra = ["--engine-config", str(config)]
    return [sys.executable, "-m", "opspec.cli", "run", str(SPEC), *RUN, *extra, "--json",
            "--trace", str(folder / "trace.jsonl"),
            "--bind", f"alarm={host}", "--bind", f"dispenser={host}"]


def _await_open(proc: subprocess.Popen[str], host: Path, name: str) -> None:
    """Return once ``proc`` holds the pty ``host`` open (Linux: /proc/PID/fd; elsewhere a
    wait of 3 s, the start-up of a run on a loaded machine)."""
    fds = Path(f"/proc/{proc.pid}/fd")
    if not fds.parent.is_dir():
        time.sleep(3)
        return
    device = os.path.realpath(host)
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        with contextlib.suppress(OSError):
            if any(os.readlink(fd) == device for fd in fds.iterdir()):
                return
        time.sleep(0.02)
    proc.kill()
    _, err = proc.communicate(timeout=5)
    raise AssertionError(f"{name}: opspec run did not open {host} (status "
                         f"{proc.returncode}):\n{err}")


def run_all(folder: Path, scenarios: dict[str, tuple[tuple[str, ...], str]] = SCENARIOS
            ) -> dict[str, BoardRun]:
    """Every scenario's board started and its `opspec run` launched, then all awaited."""
    rigs: dict[str, Rig] = {}
    runs: dict[str, subprocess.Popen[str]] = {}
    try:
        for name, (_, engine) in scenarios.items():
            place = folder / name
            place.mkdir()
            rig = rigs[name] = Rig(place)
            runs[name] = subprocess.Popen(_command(place, rig.host, engine),
                                          stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                          text=True)
        # each board starts once its run has opened the port (the runs start up meanwhile,
        # side by side), so a board's clock (--press-at-ms) starts with its run's, however
        # long the start-up took
        for name, (options, _) in scenarios.items():
            _await_open(runs[name], rigs[name].host, name)
            rigs[name].start_board(*options)
        done: dict[str, BoardRun] = {}
        for name, proc in runs.items():
            out, err = proc.communicate(timeout=300)
            trace = folder / name / "trace.jsonl"
            try:
                doc = json.loads(out)
            except ValueError as error:
                raise AssertionError(f"{name}: opspec run printed no JSON (status "
                                     f"{proc.returncode}):\n{out}\n{err}") from error
            events = [json.loads(line) for line in
                      trace.read_text(encoding="utf-8").splitlines()]
            done[name] = BoardRun(proc.returncode, doc, events, rigs[name].board_log(), err)
        return done
    finally:
        for proc in runs.values():
            if proc.poll() is None:
                proc.kill()
                proc.wait(timeout=5)
        for rig in rigs.values():
            rig.stop()
