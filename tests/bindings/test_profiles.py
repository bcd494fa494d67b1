"""Loading device profiles: the shipped ones load, and every malformed one is refused with
the file and the dotted key at fault."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from opspec.bindings.profiles import (
    load_profile,
    load_profiles,
    profiles_serving,
    resolve_profile,
)
from opspec.errors import BindingError

DEVICES = Path(__file__).resolve().parents[2] / "devices"
INVALID = Path(__file__).parent / "data" / "invalid"


def test_every_shipped_profile_loads() -> None:
    names = [p.name for p in load_profiles(DEVICES)]
    assert names == ["barcode_scanner", "battery", "bumper", "cart_motors",
                     "medication_dispenser", "range_finder", "rfid_reader"]


SPECS = DEVICES.parent / "specs"


@pytest.mark.parametrize("spec", ["medication_dispenser", "vacuum_cleaner", "toy_sumo",
                                  "medication_cart_guidance"])
def test_every_device_activity_of_the_shipped_specs_has_a_profile_operation(spec: str) -> None:
    from opspec.commands._spec import load_any_spec
    from opspec.engine.compiled import compile_package
    from opspec.engine.lanes import all_activities

    compiled = compile_package(load_any_spec(SPECS / f"{spec}.xpdl"))
    profiles = load_profiles(DEVICES)
    # the dispenser's notify_caregiver is a message to a person, not a serial device
    needed = {(a.participant, a.application) for a in all_activities(compiled)
              if a.application and a.application != "notify_caregiver"}
    assert needed
    for participant, application in sorted(needed, key=str):
        (profile,) = profiles_serving(participant or "", profiles)
        assert profile.operation_for(application, "") is not None, (participant, application)


def test_dispenser_profile_serves_alarm_and_dispenser_with_button_raising_trg_1() -> None:
    profile = load_profile(DEVICES / "medication_dispenser.toml")
    assert profile.participants == ("alarm", "dispenser")
    assert set(profile.operations) == {"alarm_on", "alarm_off", "dispense"}
    dispense = profile.operations["dispense"]
    assert dispense.command is not None
    assert dispense.command.fill({"slot": 2}) == "DISPENSE 2"
    assert dispense.timeout_s == pytest.approx(3.0)
    assert profile.operations["alarm_on"].timeout_s == pytest.approx(0.5)
    assert profile.events["report"].trigger == "trg_1"
    assert (profile.port.vid, profile.port.pid) == (0x2341, 0x0043)
    assert profile.fallback_for("alarm").then == "simulate"
    assert profile.fallback_for("dispenser").then == "abort"
    assert profile.fallback_for("dispenser").exception == "DispenserFault"
    # per-participant fallback inherits what it does not override
    # DISPENSE is not idempotent: never resent (the alarm commands are, once)
    assert (profile.fallback.retries, profile.fallback_for("dispenser").retries) == (1, 0)


def test_operation_is_found_by_application_then_activity() -> None:
    profile = load_profile(DEVICES / "medication_dispenser.toml")
    assert profile.operation_for("alarm_on", "A3").name == "alarm_on"  # type: ignore[union-attr]
    assert profile.operation_for(None, "dispense").name == "dispense"  # type: ignore[union-attr]
    assert profile.operation_for("sing", "A9") is None


def test_range_finder_reply_gives_typed_data() -> None:
    profile = load_profile(DEVICES / "range_finder.toml")
    (ok,) = profile.operations["read_range"].ok
    assert ok.match("RANGE 1.23") == {"distance": 1.23}
    assert ok.match("RANGE 2") == {"distance": 2.0}


def test_profiles_serving_and_resolve_by_name() -> None:
    profiles = load_profiles(DEVICES)
    assert [p.name for p in profiles_serving("alarm", profiles)] == ["medication_dispenser"]
    assert resolve_profile("cart_motors", DEVICES).participants == ("motors",)


# (file stem, dotted key named in the message, words of the message)
INVALID_CASES = [
    ("syntax_error", None, "not valid TOML"),
    ("missing_format", "format", "required key is missing"),
    ("unsupported_format", "format", "unsupported profile format 7"),
    ("missing_participants", "participants", "required key is missing"),
    ("participants_not_a_list", "participants", "expected a non-empty list"),
    ("unknown_top_level_key", "operation", "unknown key"),
    ("baudrate_not_an_integer", "serial.baudrate", "expected an integer"),
    ("unknown_parity", "serial.parity", "expected one of none, even, odd"),
    ("negative_timeout", "serial.reply_timeout_ms", "expected a duration >= 0"),
    ("bad_newline", "serial.newline", "expected"),
    ("bad_vid_pid", "port.vid_pid", "four hex digits"),
    ("no_operations", "operations", "at least one operation"),
    ("unbalanced_brace", "operations.dispense.command", "unbalanced"),
    ("unknown_placeholder_type", "operations.dispense.command", "unknown type 'hex'"),
    ("misspelt_operation_key", "operations.alarm_on.comand", "unknown key"),
    ("exception_not_an_identifier", "errors.ERR {reason}", "must be an identifier"),
    ("event_without_action", "events.report", "needs `trigger`"),
    ("fallback_unknown_action", "fallback.then", "\"simulate\" or \"abort\""),
    ("fallback_unknown_participant", "fallback.pump", "names no participant"),
    ("infinite_timeout", "serial.reply_timeout_ms", "at most 3.6e+06 ms, got inf"),
    ("nan_timeout", "serial.reply_timeout_ms", "got nan"),
    ("huge_settle", "serial.settle_ms", "at most 3.6e+06 ms, got 1e+300"),
    ("infinite_simulated_duration", "operations.alarm_on.simulate.duration_s",
     "at most 86400 s, got inf"),
    ("not_utf8", None, "not UTF-8 text: byte 0xe9"),
]


def test_every_invalid_case_has_a_data_file_and_vice_versa() -> None:
    assert sorted(p.stem for p in INVALID.glob("*.toml")) == sorted(c[0] for c in INVALID_CASES)


@pytest.mark.parametrize(("stem", "key", "words"), INVALID_CASES,
                         ids=[case[0] for case in INVALID_CASES])
def test_malformed_profile_is_refused_naming_file_and_key(stem: str, key: str | None,
                                                          words: str) -> None:
    path = INVALID / f"{stem}.toml"
    # file:line: key (the line, where the key is written: tests/bindings/test_profile_lines.py)
    where = re.escape(str(path)) + (r"(:\d+)?: " + re.escape(key) if key else "")
    with pytest.raises(BindingError, match=where) as caught:
        load_profile(path)
    assert words in str(caught.value)


def test_missing_profile_file_says_so() -> None:
    with pytest.raises(BindingError, match="nowhere.toml does not exist"):
        load_profile(INVALID / "nowhere.toml")


def test_unknown_profile_name_lists_the_available_ones() -> None:
    with pytest.raises(BindingError, match="available: barcode_scanner, battery, bumper"):
        resolve_profile("teapot", DEVICES)


def test_two_profiles_with_one_name_are_refused(tmp_path: Path) -> None:
    text = (DEVICES / "range_finder.toml").read_text()
    (tmp_path / "a.toml").write_text(text)
    (tmp_path / "b.toml").write_text(text)
    with pytest.raises(BindingError, match="two profiles are named 'range_finder'"):
        load_profiles(tmp_path)
