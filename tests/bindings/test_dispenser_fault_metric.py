"""The shipped dispenser spec counts device faults with its own metric (``device_faults``, a
Count of ``fault`` trace events), so ``opspec run`` and ``opspec evaluate`` report them from
the spec, and the number is the one the run summary gives per device.

Runs against the independent board process over a socat pty pair (see
test_dispenser_end_to_end.py, whose rig this reuses): garbage with noise (faults the binding
recovers from by retrying: the dose is still taken) and a jammed drawer (a fault that ends the
dose as missed).
"""

from __future__ import annotations

import json
import shutil

import pytest

from opspec.cli import main

from .conftest import needs_pty
from .test_dispenser_end_to_end import SPEC, device, rig, run, totals  # noqa: F401  (fixture)

pytestmark = [
    needs_pty,
    pytest.mark.skipif(shutil.which("socat") is None,
                       reason="needs socat for the pty pair: run scripts/system-deps.sh"),
]


@pytest.mark.parametrize(("board", "outcome"), [
    (("--garbage", "1", "--noise"), "doses_taken"),
    (("--jam",), "doses_missed"),
])
def test_the_spec_counts_the_device_faults_the_run_summary_reports(
        rig, capsys, tmp_path, board, outcome):  # noqa: F811  (the imported fixture)
    # garbage is retried at its timeout, over an hour simulated at 5000x: the user's early
    # press is kept for the dose's wait (test_dispenser_end_to_end.py, the garbage test)
    _, doc, events, _ = run(rig, capsys, tmp_path, *board, engine="message_ttl = 86400\n")
    faults = device(doc)["faults"]
    assert faults, "the board was told to misbehave: the binding must report faults"
    assert doc["metrics"]["device_faults"] == {"kind": "count", "total": len(faults)}
    assert len([e for e in events if e.get("kind") == "fault"]) == len(faults)
    assert totals(doc)[outcome] == 1


def test_simulated_devices_never_fault(capsys):
    status = main(["run", str(SPEC), "--days", "2", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0
    assert doc["metrics"]["device_faults"] == {"kind": "count", "total": 0}
    assert doc["metrics"]["doses_due"]["total"] == 8
