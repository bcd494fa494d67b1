"""Safety monitors declared in a BPMN file: several `opspec:Monitor` extension elements are
several monitors, each watched (as several `opspec:Monitor` ExtendedAttributes are in XPDL),
with no "given twice; the last one counts" warning."""

from __future__ import annotations

from pathlib import Path

import opspec
from opspec.xpdl.loader import load_package

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.bpmn"
MONITORS = ('<opspec:Monitor Value="min_gap dispense 4h"/>\n'
            '<opspec:Monitor Value="never notify_caregiver"/>\n')


def _with_monitors(tmp_path: Path) -> Path:
    text = SPEC.read_text(encoding="utf-8")
    assert text.count("</opspec:Metrics>") == 1
    out = tmp_path / "dispenser_monitored.bpmn"
    out.write_text(text.replace("</opspec:Metrics>", "</opspec:Metrics>\n" + MONITORS),
                   encoding="utf-8")
    return out


def test_two_monitors_are_two_monitors_without_a_duplicate_warning(tmp_path: Path) -> None:
    path = _with_monitors(tmp_path)
    result = load_package(path)
    assert result.ok, result.diagnostics
    assert not [d for d in result.diagnostics if d.code == "duplicate-directive"]
    outcome = opspec.run(path, seed=1, days=2,
                         user_model=SPEC.with_name("medication_dispenser.users.toml"))
    watched = sorted(m.monitor for m in outcome.monitors)
    assert len(watched) == 2 and "dispense" in watched[0] and "notify_caregiver" in watched[1]
