"""Snapshots of the walkthrough's main screen in its key states (pytest-textual-snapshot).

Deterministic: the clock is simulated and paused; nothing on screen reads the wall clock.
Update after an intended change with ``pytest tests/tui --snapshot-update``."""

from __future__ import annotations

import pytest

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession

pytest.importorskip("pytest_textual_snapshot")


def paused_app(compiled) -> WalkthroughApp:
    session = WalkSession(compiled)
    session.paused = True
    return WalkthroughApp(session, title="Smart medication dispenser")


@pytest.mark.parametrize("size", [(80, 24), (120, 36)], ids=["80x24", "120x36"])
def test_idle_before_the_first_dose(compiled, snap_compare, size):
    assert snap_compare(paused_app(compiled), terminal_size=size)


@pytest.mark.parametrize("size", [(80, 24), (120, 36)], ids=["80x24", "120x36"])
def test_alarm_ringing(compiled, snap_compare, size):
    assert snap_compare(paused_app(compiled), press=["u"], terminal_size=size)


def test_choice_of_buttons_offered(compiled, snap_compare):
    assert snap_compare(paused_app(compiled), press=["u", "a", "w", "w", "w", "a"],
                        terminal_size=(80, 24))


def lab_app(compiled) -> WalkthroughApp:
    session = WalkSession(compiled)
    session.paused = True
    return WalkthroughApp(session, title="Smart medication dispenser", large=True,
                          high_contrast=True)


@pytest.mark.parametrize("size", [(64, 20), (80, 24)], ids=["64x20", "80x24"])
def test_large_high_contrast_alarm(compiled, snap_compare, size):
    # a big terminal font leaves few cells: the person's panel first, tall buttons
    assert snap_compare(lab_app(compiled), press=["u"], terminal_size=size)


def test_large_high_contrast_after_the_wrong_button(compiled, snap_compare):
    assert snap_compare(lab_app(compiled), press=["u", "a", "a", "b"], terminal_size=(80, 24))
