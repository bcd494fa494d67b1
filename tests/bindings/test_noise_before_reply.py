"""A valid reply after noise is read: the independent board (dispenser_board.py, over a socat
pty pair: board_runs.py) answers DISPENSE with a debug line, an unknown line, a garbled line and a cut-off
frame first, then the real reply in two pieces. The drawer dispensed, so the dose is taken,
never recorded as missed, DISPENSE is sent once (it is not idempotent: a resend could drop a
second dose), and the noise is reported as device faults, not lost.

devices/README.md: "Lines starting with # are debug output and ignored"; a reply is the
first line matching one of the operation's reply templates within its timeout.
"""

from __future__ import annotations

import shutil

import pytest

from .conftest import needs_pty
from .test_dispenser_end_to_end import assert_every_dose_decided, device, totals

pytestmark = [
    needs_pty,
    pytest.mark.skipif(shutil.which("socat") is None,
                       reason="needs socat for the pty pair: run scripts/system-deps.sh"),
]


def test_a_reply_after_noise_and_partial_frames_is_read_and_the_dose_is_taken(board_runs):
    run = board_runs["noise-before"]                # the board's --noise-before
    doc, events, log = run.doc, run.events, run.log
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1 and totals(doc)["doses_missed"] == 0
    assert log.count("RX DISPENSE 1") == 1          # read, not resent
    exchanges = [e for e in events if e.get("kind") == "device.exchange"
                 and (e.get("data") or {}).get("command") == "DISPENSE 1"]
    assert [e["data"]["reply"] for e in exchanges] == ["OK DISPENSED 1"]
    faults = device(doc)["faults"]
    # the noise is on record: one fault for the attempt, naming what came before the reply
    assert [(f["fault"], f["action"]) for f in faults] == [("garbage", "none")]
    assert "before the reply 'OK DISPENSED 1', which was read" in faults[0]["message"]
    assert "HELLO THERE" in faults[0]["message"] and "2 more line(s)" in faults[0]["message"]
    assert device(doc)["mode"]["dispenser"] == "device"
