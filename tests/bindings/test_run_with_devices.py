"""`opspec run --bind`: the dispenser spec driving an emulated device over a real
pseudo-terminal or a socket, in wall-clock time, with every fault named and the run going on."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from opspec.bindings import load_profile
from opspec.bindings.emulator import Behaviour, EmulatedDevice, PtyEmulator, SocketEmulator
from opspec.cli import main

from .conftest import DATA, DEVICES, needs_pty

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
# 00:00 → 10:00 at 20,000x (1.8 s): device replies take wall time, so leave slack after 08:00
FIRST_DOSE = ["--until", "36000", "--realtime", "--speed", "20000"]


class ButtonPressingDevice(EmulatedDevice):
    """The dispenser board with a user who presses *report* right after each alarm."""

    server: Any = None

    def handle_line(self, line: str) -> list[Any]:
        actions = super().handle_line(line)
        if line.strip() == "ALARM ON" and self.server is not None:
            self.server.send_event("report", after_s=0.002)
        return actions


@pytest.fixture
def board():
    servers: list[Any] = []

    def start(*, fault: str = "none", on: str = "pty", presses: bool = False,
              profile: Path = DEVICES / "medication_dispenser.toml") -> Any:
        cls = ButtonPressingDevice if presses else EmulatedDevice
        device = cls(load_profile(profile), Behaviour.parse(fault))
        server = PtyEmulator(device) if on == "pty" else SocketEmulator(device)
        device.server = server
        servers.append(server)
        server.start()
        return server

    yield start
    for server in servers:
        server.stop()


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict[str, Any] | None,
                                                                 str]:
    status = main(["run", str(SPEC), *args])
    captured = capsys.readouterr()
    doc = json.loads(captured.out) if "--json" in args and captured.out.strip() else None
    return status, doc, captured.out + captured.err


def script(tmp_path: Path, *steps: tuple[str, str]) -> str:
    path = tmp_path / "user.toml"
    body = ",".join(f'["{w}", "{a}"]' for w, a in steps)
    path.write_text(f'otherwise = "complete"\nsteps = [{body}]\n', encoding="utf-8")
    return str(path)


@needs_pty
def test_dispenser_over_a_pseudo_terminal_takes_the_dose(board, capsys, tmp_path):
    server = board(on="pty")
    status, doc, _ = run(capsys, *FIRST_DOSE, "--json", "--bind", f"alarm={server.url}",
                         "--bind", f"dispenser={server.url}", "--script",
                         script(tmp_path, ("after trg_2 60s", "press_report")))
    assert status == 0
    assert doc["metrics"]["doses_taken"]["total"] == 1
    device = doc["devices"]["alarm, dispenser"]
    assert device["url"] == server.url
    assert device["mode"] == {"alarm": "device", "dispenser": "device"}
    assert device["latency_ms"]["count"] >= 2          # ALARM ON and DISPENSE answered
    assert device["faults"] == []
    assert doc["drift"]["events"] > 0


@needs_pty
def test_button_on_the_device_reports_for_the_user(board, capsys, tmp_path):
    server = board(on="pty", presses=True)
    status, doc, _ = run(capsys, *FIRST_DOSE, "--json", "--bind", f"alarm={server.url}",
                         "--script", script(tmp_path, ("never", "press_report")))
    assert status == 0
    assert doc["metrics"]["doses_taken"]["total"] == 1
    assert doc["metrics"]["doses_missed"]["total"] == 0


def test_dispenser_over_a_socket(board, capsys, tmp_path):
    server = board(on="socket")
    status, doc, _ = run(capsys, *FIRST_DOSE, "--json", "--bind", f"alarm={server.url}",
                         "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0
    assert doc["metrics"]["doses_taken"]["total"] == 1
    assert doc["devices"]["alarm"]["latency_ms"]["count"] >= 1


@pytest.mark.parametrize("fault, named", [
    ("silent", "timeout"),
    ("garbage", "garbage"),
], ids=["no-reply", "garbage"])
def test_misbehaving_alarm_is_a_named_fault_and_the_alarm_goes_on_simulated(
        fault, named, board, capsys, tmp_path):
    server = board(on="pty", fault=fault, profile=DATA / "test_dispenser.toml")
    trace = tmp_path / "trace.jsonl"
    # reply timeouts are wall-clock (300 ms): at 20,000x two of them and the 300 ms hold
    # for a late reply between them span about 5 h
    status, doc, _ = run(capsys, "--until", "50000", "--realtime", "--speed", "20000",
                         "--json", "--bind", f"alarm:test_dispenser={server.url}",
                         "--devices", str(DATA), "--trace", str(trace),
                         "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    faults = doc["devices"]["alarm"]["faults"]
    assert any(f["fault"] == named for f in faults)
    assert doc["devices"]["alarm"]["mode"]["alarm"] == "simulated"
    # the device's fallback kept the dose going: the user still got it (and the 12:00 dose
    # too, when the faults were over quickly enough)
    assert doc["metrics"]["doses_taken"]["total"] >= 1
    kinds = [json.loads(line)["kind"] for line in trace.read_text().splitlines()[1:]]
    assert "fault" in kinds and kinds[-1] == "run.ended"
    assert status == 1           # a device fault is a problem worth an exit status


def test_unopenable_port_stops_the_run_before_it_begins(capsys):
    status, _, output = run(capsys, "--bind", "alarm=/dev/opspec-no-such-port")
    assert status == 2
    assert "/dev/opspec-no-such-port" in output and "No such file" in output
    assert ", seed " not in output   # nothing ran: no header "opspec run: NAME (SPEC), seed N, ..."
    assert "Traceback" not in output


def test_auto_without_a_device_falls_back_to_simulated_and_says_so(capsys, tmp_path):
    status, _, output = run(capsys, "--until", "29700", "--timeline", "none",
                            "--bind", "alarm=auto",
                            "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0
    assert "using the simulated alarm" in output
    assert "alarm simulated" in output


@needs_pty
def test_device_faults_are_on_the_screen_with_the_fallback_taken(board, capsys, tmp_path):
    server = board(on="pty", fault="garbage", profile=DATA / "test_dispenser.toml")
    # garbage ends an attempt at its timeout (a reply may follow noise): timeout, hold,
    # resend, timeout, 3 x 300 ms (wall), 2 simulated hours at 8,000x before 12:00
    status, _, output = run(capsys, "--until", "43000", "--realtime", "--speed", "8000",
                            "--timeline", "brief", "--bind", f"alarm:test_dispenser={server.url}",
                            "--devices", str(DATA),
                            "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 1
    assert "fault garbage:" in output and "(then retry)" in output
    assert "(then simulate)" in output
    assert "using the simulated alarm from now on" in output
    assert "Traceback" not in output


def test_bind_of_a_participant_the_spec_lacks_is_a_usage_error_naming_the_bindable_ones(
        capsys):
    # before: accepted, announced as "a real device", and a 10 h run on the wall clock at 1x
    status, _, output = run(capsys, "--timeline", "none",
                            "--bind", "motors=emulator://cart_motors")
    assert status == 2
    assert "--bind 'motors=emulator://cart_motors': the spec has no participant 'motors'" \
        in output
    assert "bindable participants of this spec: alarm, dispenser" in output
    assert ", seed " not in output   # nothing ran: no header "opspec run: NAME (SPEC), seed N, ..."


def test_speed_with_auto_falling_back_to_simulation_says_it_has_no_effect(capsys, tmp_path):
    status, _, output = run(capsys, "--until", "29700", "--timeline", "none", "--speed", "5",
                            "--bind", "alarm=auto",
                            "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0
    assert "--speed 5 has no effect: no device port is open" in output
    assert "wall clock" not in output.split("--speed 5 has no effect")[0]  # engine line


def test_an_in_process_emulator_is_not_called_a_real_device(capsys, tmp_path):
    status, _, output = run(capsys, "--until", "36000", "--speed", "20000", "--timeline",
                            "none", "--bind", "alarm=emulator://medication_dispenser",
                            "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0
    assert "real device" not in output
    assert "only in-process emulators are bound: running on the wall clock" in output
    assert "wall clock at 20000x" in output


def test_a_command_still_unanswered_when_the_run_ends_is_reported(capsys, tmp_path):
    # ALARM ON goes out at 08:00; the run stops 1200 simulated s (60 ms of wall time) later,
    # long before the silent board's 500 ms timeout (or its retry)
    trace = tmp_path / "trace.jsonl"
    url = "emulator://medication_dispenser?fault=silent"
    status, doc, _ = run(capsys, "--until", "30000", "--realtime", "--speed", "20000",
                         "--json", "--trace", str(trace), "--bind", f"alarm={url}",
                         "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0            # unfinished work is reported, not a fault
    pending = doc["devices"]["alarm"]["pending"]
    assert pending and {p["state"] for p in pending} <= {"sent", "held"}
    assert pending[0]["activity"] == "sound_alarm" and pending[0]["command"] == "ALARM ON"
    events = [json.loads(line) for line in trace.read_text().splitlines()[1:]]
    (traced,) = [e for e in events if e["kind"] == "device.pending"]
    assert traced["data"]["pending"][0]["command"] == "ALARM ON"
    # and on the screen
    _, _, output = run(capsys, "--until", "30000", "--realtime", "--speed", "20000",
                       "--timeline", "none", "--bind", f"alarm={url}",
                       "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert "unfinished at the end: alarm: sound_alarm (instance" in output
