"""A cron ``timeCycle`` (Camunda's Quartz form ``sec min hour dom month dow``, Unix's five
fields) is read, through croniter, where it is a fixed period, and refused at its line naming
why where it is not (issue 28: "cron timeCycle is read (a well-kept cron library) or refused
at its line").

BPMN 2.0 §10.4.5 (Timer Event Definition): "timeCycle ... the format of the expression depends
on the expression language"; Camunda 7 reads a cron expression there ("0 0/5 * * * ?": every
five minutes). Expected times worked by hand: every 5 minutes from 00:00 over one hour fires
at 0, 300, …, 3300 s (12 starts before 3600 s); "0 8 * * *" fires at 08:00 of each day:
28 800, 115 200 and 201 600 s over three days.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec


def _diagram(tmp_path: Path, cycle: str) -> Path:
    path = tmp_path / "cron.bpmn"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d"
    targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start">
      <bpmn:timerEventDefinition>
        <bpmn:timeCycle>{cycle}</bpmn:timeCycle>
      </bpmn:timerEventDefinition>
    </bpmn:startEvent>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="end"/>
    <bpmn:endEvent id="end"/>
  </bpmn:process>
</bpmn:definitions>
""", encoding="utf-8")
    return path


def _starts(path: Path, seconds: float) -> list[float]:
    outcome = opspec.run(path, seed=1, until=seconds)
    return [e.time for e in outcome.trace if e.kind == "process.started"]


@pytest.mark.parametrize("cycle", ["0 0/5 * * * ?", "*/5 * * * *", "0 0/5 * 1/1 * ? *"])
def test_a_cron_every_five_minutes_starts_the_process_every_five_minutes(
        tmp_path: Path, cycle: str) -> None:
    path = _diagram(tmp_path, cycle)
    _package, report = validate_spec(path)
    assert not [d for d in report.diagnostics if d.severity is Severity.ERROR]
    [said] = [d for d in report.diagnostics if d.code == "cron-timer"]
    assert said.location.line == 7 and "R/T00:00:00/PT300S" in said.message
    assert _starts(path, 3599) == [300.0 * k for k in range(12)]


def test_a_daily_cron_fires_at_its_time_of_day(tmp_path: Path) -> None:
    path = _diagram(tmp_path, "0 8 * * *")
    assert _starts(path, 3 * 86_400) == [28_800.0, 115_200.0, 201_600.0]


@pytest.mark.parametrize(("cycle", "said"), [
    ("0 8 * * MON-FRI", "certain days only (its day of the week field)"),
    ("0 0 8 L * ?", "certain days only (its day of the month field)"),
    ("0 9,17 * * *", "uneven times of the day (09:00:00, 17:00:00)"),
    ("0 0 12 * * ? 2027", "names years (2027)"),
    ("0 61 * * *", "cannot read the cron timeCycle"),
])
def test_a_cron_that_is_no_fixed_period_is_refused_at_its_line(tmp_path: Path, cycle: str,
                                                               said: str) -> None:
    _package, report = validate_spec(_diagram(tmp_path, cycle))
    [error] = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert error.code == "bad-timer" and error.location.line == 7
    assert said in error.message, error.message
