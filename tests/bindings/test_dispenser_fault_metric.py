"""The shipped dispenser spec counts device faults with its own metric (``device_faults``, a
Count of ``fault`` trace events), so ``opspec run`` and ``opspec evaluate`` report them from
the spec, and the number is the one the run summary gives per device.

Reads the runs against the independent board process over socat pty pairs that
test_dispenser_end_to_end.py reads too (board_runs.py): garbage with noise (faults the binding
recovers from by retrying: the dose is still taken) and a jammed drawer (a fault that ends the
dose as missed).
"""

from __future__ import annotations

import json
import shutil

import pytest

from opspec.cli import main

from .board_runs import SPEC
from .conftest import needs_pty
from .test_dispenser_end_to_end import device, totals

pytestmark = [
    needs_pty,
    pytest.mark.skipif(shutil.which("socat") is None,
                       reason="needs socat for the pty pair: run scripts/system-deps.sh"),
]


@pytest.mark.parametrize(("board", "outcome"), [
    ("garbage", "doses_taken"),     # --garbage 1 --noise, messages kept a day
    ("jam", "doses_missed"),        # --jam
])
def test_the_spec_counts_the_device_faults_the_run_summary_reports(
        board_runs, board, outcome):
    # garbage is retried at its timeout, over an hour simulated at 5000x: the user's early
    # press is kept for the dose's wait (test_dispenser_end_to_end.py, the garbage test)
    doc, events = board_runs[board].doc, board_runs[board].events
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
