"""`opspec show`'s text names what an activity's SISARL directives add: the message it raises
(the dispenser's alarm trg_2 that starts the user's workflow, the user's report trg_1), its
start and end triggers, its simulated duration, its CPU demand, and what a built-in reads and
writes. It printed none of them, so the text never showed how the device and the user's
workflows are linked; a rule trigger showed as 'rule' without its condition."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


def _lines(spec: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, str]:
    """Each activity's line, by activity id."""
    main(["show", str(spec)])
    out: dict[str, str] = {}
    for line in capsys.readouterr().out.splitlines():
        words = line.split()
        if line.startswith("    ") and len(words) > 1 and not line.startswith("     "):
            out.setdefault(words[0], line.strip())
    return out


def test_the_messages_linking_device_and_user_are_shown(
        capsys: pytest.CaptureFixture[str]) -> None:
    lines = _lines(SPECS / "medication_dispenser.xpdl", capsys)
    assert lines["sound_alarm"].endswith(", join XOR, raises message:trg_2")
    assert lines["press_report"].endswith(", manual, raises message:trg_1")


def test_durations_cpu_demands_and_built_ins_are_shown(
        capsys: pytest.CaptureFixture[str]) -> None:
    lines = _lines(SPECS / "vacuum_cleaner.xpdl", capsys)
    assert lines["read_range"].endswith(", automatic, cpu 0.002 s")
    assert lines["back_up"].endswith(", automatic, takes ConstantParameter(value=0.6)")
    assert lines["arbiter"].endswith(
        "built-in arbiter motor_cmd <- escape_cmd, avoid_cmd, wander_cmd")
    assert lines["push_range"].endswith("built-in push distance -> channel range")
    assert lines["pull_range"].endswith("built-in pull seen <- channel range")
    assert lines["go_dock"].endswith("built-in mode-change to dock")
    voter = _lines(SPECS / "toy_sumo.xpdl", capsys)["choose_hit"]
    assert voter.endswith("built-in voter hit_cmd <- vote_range, vote_edge "
                          "(options turn_random, charge)")


def test_an_activity_trigger_and_a_rule_s_condition_are_shown(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = (SPECS / "medication_dispenser.xpdl").read_text(encoding="utf-8")
    spec = tmp_path / "d.xpdl"
    spec.write_text(text.replace(
        '<ExtendedAttribute Name="opspec:Raises" Value="message:trg_2"/>',
        '<ExtendedAttribute Name="opspec:Raises" Value="message:trg_2"/>'
        '<ExtendedAttribute Name="opspec:EndTrigger" Value="rule:alarms &gt; 2"/>'),
        encoding="utf-8")
    line = _lines(spec, capsys)["sound_alarm"]
    assert line.endswith(", ends on rule alarms > 2, raises message:trg_2")


def test_arrivals_run_length_and_message_ttl_are_shown(
        capsys: pytest.CaptureFixture[str]) -> None:
    main(["show", str(ROOT / "tests" / "bpmn" / "data" / "simulation" / "qbp_loan.bpmn")])
    assert ("  directives: arrivals every ExponentialDistribution(mean=600), 200 in all"
            in capsys.readouterr().out.splitlines())
    main(["show", str(SPECS / "vacuum_cleaner.xpdl")])
    assert "Run length: 1.25 h" in capsys.readouterr().out.splitlines()
    main(["show", str(SPECS / "medication_dispenser.xpdl")])
    assert ("Message TTL: 1 min (a message nobody waits for)"
            in capsys.readouterr().out.splitlines())
