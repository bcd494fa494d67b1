"""A ratio metric is declared a proportion in the spec (``Proportion="true"`` on its
``opspec:Ratio``, docs/sisarl-xpdl.md), not guessed from a run's numbers: read from XPDL and
BPMN, written back, kept by the stored definitions, and refused where it cannot be true."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.evaluation.describe import metric_record
from opspec.model import MetricKind
from opspec.xpdl import load_package, parse_bytes
from opspec.xpdl.writer import write_xpdl

ROOT = Path(__file__).resolve().parents[2]
HEAD = ('<?xml version="1.0"?>\n<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" '
        'xmlns:opspec="urn:opspec:sisarl:1" Id="pkg">')
COUNTS = ('<opspec:Count Name="due" Event="process.started"/>\n'
          '<opspec:Count Name="missed" Event="activity.completed" Activity="miss"/>\n')


def metrics(body: str):
    """The spec's metrics, declared one per line from line 3 on (``COUNTS`` first)."""
    text = (f'{HEAD}\n<ExtendedAttributes><ExtendedAttribute Name="opspec:Metrics">\n'
            f"{COUNTS}{body}\n</ExtendedAttribute></ExtendedAttributes></Package>")
    return parse_bytes(text.encode(), path="m.xpdl")


def proportions(package) -> dict[str, bool]:
    return {m.name: m.proportion for m in package.metrics if m.kind is MetricKind.RATIO}


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_dispensers_declare_their_proportions_and_not_alarms_per_dose(spec):
    result = load_package(ROOT / "specs" / spec)
    assert result.ok and result.package is not None
    assert proportions(result.package) == {"alarms_per_dose": False, "taken_rate": True,
                                           "missed_rate": True}


def test_the_toy_sumo_declares_its_win_rate_a_proportion():
    result = load_package(ROOT / "specs" / "toy_sumo.xpdl")
    assert result.package is not None and proportions(result.package) == {"win_rate": True}


@pytest.mark.parametrize("template", ["pill", "stove"])
def test_opspec_new_templates_declare_their_rates_proportions(template):
    from opspec.commands.new import render

    text = render(template)[f"{template}.xpdl"]
    package = parse_bytes(text.encode(), path=f"{template}.xpdl").package
    assert package is not None and set(proportions(package).values()) == {True}


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_declaration_survives_writing_and_reading_back(spec):
    package = load_package(ROOT / "specs" / spec).package
    assert package is not None
    written = write_xpdl(package)
    assert written.count(b'Proportion="true"') == 2
    again = parse_bytes(written, path="w.xpdl").package
    assert again is not None
    assert proportions(again) == proportions(package)
    assert [(m.name, m.numerator, m.denominator, m.proportion, m.description)
            for m in again.metrics] == [
        (m.name, m.numerator, m.denominator, m.proportion, m.description)
        for m in package.metrics]


def test_an_undeclared_ratio_is_written_without_the_attribute():
    result = metrics('<opspec:Ratio Name="r" Numerator="missed" Denominator="due"/>')
    assert result.ok and result.package is not None
    assert b"Proportion" not in write_xpdl(result.package)
    assert proportions(result.package) == {"r": False}


def test_the_stored_definition_carries_the_declaration():
    result = metrics('<opspec:Ratio Name="r" Numerator="missed" Denominator="due" '
                     'Proportion="true"/>\n<opspec:Ratio Name="s" Numerator="missed" '
                     'Denominator="due" Proportion="false"/>')
    assert result.ok and result.package is not None
    records = {m.name: metric_record(m) for m in result.package.metrics}
    assert records["r"]["proportion"] is True and records["s"]["proportion"] is False


def test_the_compiled_script_keeps_the_declaration():
    from opspec.model import codec

    package = load_package(ROOT / "specs" / "medication_dispenser.xpdl").package
    assert package is not None
    again = codec.loads(codec.dumps(package))
    assert proportions(again) == proportions(package)


@pytest.mark.parametrize(("body", "words", "line"), [
    ('<opspec:Ratio Name="r" Numerator="missed" Denominator="due" Proportion="yes"/>',
     "Proportion must be true or false", 6),
    ('<opspec:Count Name="c" Event="e" Proportion="true"/>', "declared of a ratio", 6),
    (('<opspec:Duration Name="lat" Unit="s"><opspec:From Event="a"/><opspec:To Event="b"/>'
      '</opspec:Duration>\n<opspec:Ratio Name="r" Numerator="missed" Denominator="lat" '
      'Proportion="true"/>'), "'lat' is not an opspec:Count", 7),
], ids=["not-a-boolean", "on-a-count", "of-a-duration"])
def test_a_declaration_that_cannot_hold_is_an_error_at_its_line(body, words, line):
    result = metrics(body)
    [error] = result.errors
    assert error.code == "bad-metric" and words in error.message and error.hint
    assert error.location.line == line
