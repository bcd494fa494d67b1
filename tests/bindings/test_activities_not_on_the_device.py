"""A bound participant's automatic activity whose Application id is no operation of its
profile runs by itself (the engine routes automatic activities to a device by Application id
only): a misspelt ``[operations.alarm_onn]`` looked like a working device, bound, no fault,
the buzzer never asked. The run now says so before it starts."""

from __future__ import annotations

from pathlib import Path

from opspec.bindings.attach import attach_devices
from opspec.commands._spec import load_any_spec
from opspec.engine.compiled import compile_package

from .conftest import DEVICES

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
URL = "emulator://medication_dispenser"


def _compiled():  # type: ignore[no-untyped-def]
    return compile_package(load_any_spec(SPEC))


def test_a_misspelt_operation_is_said_to_run_by_itself(tmp_path: Path) -> None:
    text = (DEVICES / "medication_dispenser.toml").read_text(encoding="utf-8")
    (tmp_path / "medication_dispenser.toml").write_text(
        text.replace("[operations.alarm_on]", "[operations.alarm_onn]"), encoding="utf-8")
    with attach_devices([f"alarm={URL}"], tmp_path, spec=_compiled()) as devices:
        assert devices.notes[1:] == [
            ("alarm: application 'alarm_on' (sound_alarm in notify_workflow) is not an "
            "operation of profile medication_dispenser, so it runs by itself, not on the "
            "device (operations: alarm_off, alarm_onn, dispense)")]


def test_the_shipped_profile_covers_the_alarm() -> None:
    with attach_devices([f"alarm={URL}"], DEVICES, spec=_compiled()) as devices:
        assert len(devices.notes) == 1 and "bound to" in devices.notes[0]


def test_the_caregivers_message_is_said_to_be_no_device_work() -> None:
    with attach_devices([f"dispenser={URL}"], DEVICES, spec=_compiled()) as devices:
        assert devices.notes[1:] == [
            ("dispenser: application 'notify_caregiver' (notify_caregiver in notify_workflow, "
            "report_fault in notify_workflow) is not an operation of profile "
            "medication_dispenser, so it runs by itself, not on the device (operations: "
            "alarm_off, alarm_on, dispense)")]


def test_without_a_spec_nothing_is_checked() -> None:
    with attach_devices([f"alarm={URL}"], DEVICES) as devices:
        assert len(devices.notes) == 1


def test_an_event_raising_a_trigger_the_spec_never_names_is_said_to_be_lost(
        tmp_path: Path) -> None:
    text = (DEVICES / "medication_dispenser.toml").read_text(encoding="utf-8")
    (tmp_path / "medication_dispenser.toml").write_text(
        text.replace('trigger = "trg_1"', 'trigger = "trg_11"'), encoding="utf-8")
    with attach_devices([f"alarm={URL}"], tmp_path, spec=_compiled()) as devices:
        assert devices.notes[1:] == [(
            "medication_dispenser: event 'report' raises trigger 'trg_11', which this spec "
            "never catches: such lines from the device ('BUTTON REPORT') are lost (the spec's "
            "triggers: trg_1, trg_2)")]
