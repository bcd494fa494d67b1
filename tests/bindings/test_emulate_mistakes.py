"""``opspec devices emulate`` and ``emulator://`` given the numbers a designer mistypes: a
delay or duration of ``inf``, ``nan``, a negative one. Each is refused in one line before the
emulator starts; before, ``inf`` killed the emulator's thread with a traceback while the
command still claimed to be emulating, and ``--duration inf`` was an internal error."""

from __future__ import annotations

import pytest

from opspec.bindings import bind
from opspec.bindings.emulator import Behaviour
from opspec.bindings.profiles import DeviceProfile
from opspec.cli import main
from opspec.errors import BindingError

from .conftest import DEVICES

EMULATE = ["devices", "emulate", "medication_dispenser", "--profiles", str(DEVICES), "--quiet"]


@pytest.mark.parametrize("after", ["inf", "nan", "-5", "1e300", "soon"])
def test_an_event_delay_that_no_wait_can_take_is_refused(
        capsys: pytest.CaptureFixture[str], after: str) -> None:
    assert main([*EMULATE, "--event", f"report@{after}", "--duration", "0.05"]) == 2
    captured = capsys.readouterr()
    assert f"--event 'report@{after}': expected NAME@SECONDS" in captured.err
    assert "Traceback" not in captured.err and "Emulating" not in captured.out


@pytest.mark.parametrize("duration", ["inf", "nan", "-1", "1e300"])
def test_a_duration_that_no_wait_can_take_is_a_usage_error(
        capsys: pytest.CaptureFixture[str], duration: str) -> None:
    with pytest.raises(SystemExit) as stopped:
        main([*EMULATE, "--duration", duration])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert f"--duration: '{duration}': expected seconds from 0 to" in err
    assert "internal error" not in err


@pytest.mark.parametrize("fault", ["late:inf", "late:nan", "late:-5", "silent:-1",
                                   "disconnect:-2"])
def test_a_fault_with_an_impossible_number_is_refused(fault: str) -> None:
    with pytest.raises(BindingError, match=f"unknown emulator fault '{fault}'"):
        Behaviour.parse(fault)


def test_good_numbers_still_parse() -> None:
    from opspec.bindings.emulator import parse_event

    assert parse_event("report@5") == ("report", 5.0)
    assert parse_event("report") == ("report", 0.0)
    assert Behaviour.parse("late:300").delay_s == pytest.approx(0.3)
    assert Behaviour.parse("silent:0").count == 0


def test_an_emulator_url_with_an_infinite_event_delay_stops_before_the_run(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match=r"event= 'report@inf': expected NAME@SECONDS"):
        bind("alarm", "emulator://medication_dispenser?event=report@inf", dispenser_profile)


def test_emulate_says_how_to_bind_every_participant_of_the_device(
        capsys: pytest.CaptureFixture[str]) -> None:
    # binding only the first (alarm) left the drawer simulated without a word
    assert main([*EMULATE, "--port", "socket://127.0.0.1:0", "--duration", "0.05"]) == 0
    out = capsys.readouterr().out
    line = next(text for text in out.splitlines() if "bind it with:" in text)
    url = line.split("--bind alarm=", 1)[1].split()[0]
    assert line.strip() == f"bind it with: --bind alarm={url} --bind dispenser={url}"


def test_a_socket_port_in_use_says_what_to_do(capsys) -> None:
    """``Address already in use`` alone left the designer guessing; the refusal says another
    program listens there and how to get a free port."""
    import socket

    from opspec.cli import main

    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        status = main(["devices", "emulate", "medication_dispenser", "--port",
                       f"socket://127.0.0.1:{port}", "--duration", "0.1", "--quiet"])
    err = capsys.readouterr().err
    assert status == 2
    assert f"cannot listen on 127.0.0.1:{port}: Address already in use" in err
    assert "while attempting" not in err
    assert "another program listens on that port" in err and "socket://127.0.0.1:0" in err
