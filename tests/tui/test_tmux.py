"""The real `opspec walkthrough` in a real terminal (tmux): keys in, screen out."""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest
from walkthrough_inputs import SPEC

pytestmark = pytest.mark.skipif(shutil.which("tmux") is None,
                                reason="tmux is not installed (scripts/system-deps.sh installs it)")


# a private server: the test never touches the user's own tmux sessions
SOCKET = f"opspec-test-{uuid.uuid4().hex[:8]}"


@pytest.fixture(autouse=True)
def _a_server_of_its_own():
    """Each test its own tmux server. With one server for the module, killing a test's last
    session shut the server down while the next test's `new-session` could already be
    talking to it (a loaded clean-clone run: `new-session` exit status 1)."""
    global SOCKET
    SOCKET = f"opspec-test-{uuid.uuid4().hex[:8]}"
    yield
    subprocess.run(["tmux", "-L", SOCKET, "kill-server"], capture_output=True, check=False)


def tmux(*args: str) -> str:
    return subprocess.run(["tmux", "-L", SOCKET, *args], capture_output=True, text=True,
                          check=True).stdout


def wait_for(session: str, *texts: str, timeout: float = 30.0) -> str:
    """The screen once every one of ``texts`` shows on it (a frame Textual is still drawing
    may show some of them only: look again rather than judge a half-drawn screen)."""
    deadline = time.monotonic() + timeout
    screen = ""
    while time.monotonic() < deadline:
        screen = tmux("capture-pane", "-p", "-t", session)
        if all(text in screen for text in texts):
            return screen
        time.sleep(0.2)
    missing = [text for text in texts if text not in screen]
    raise AssertionError(f"{missing!r} never appeared; the screen was:\n{screen}")


def test_walkthrough_in_tmux_shows_the_alarm_and_says_where_the_recording_is(tmp_path):
    session = f"opspec-{uuid.uuid4().hex[:8]}"
    record = tmp_path / "walk.json"
    command = f"{sys.executable} -m opspec.cli walkthrough {SPEC} --record {record}"
    tmux("new-session", "-d", "-s", session, "-x", "100", "-y", "30")
    try:
        tmux("set-option", "-t", session, "remain-on-exit", "on")
        tmux("send-keys", "-t", session, command, "Enter")
        wait_for(session, "you perform the lane")
        tmux("send-keys", "-t", session, "space")
        tmux("send-keys", "-t", session, "u")
        screen = wait_for(session, "THE DEVICE CALLS YOU", "Hear the alarm",
                          "alarm: ((( RINGING ))) since 08:00")
        assert "Hear the alarm" in screen and "08:00:00" in screen
        assert "alarm: ((( RINGING ))) since 08:00" in screen      # the device panel
        assert "deadline wait_report (#2) in 05:00" in screen
        tmux("send-keys", "-t", session, "a")
        wait_for(session, "Walk to the dispenser")
        # the clock dropped to real time at the call: the person can answer the alarm
        assert "08:00:00  1x  PAUSED" in screen          # (paused by the space above)
        tmux("send-keys", "-t", session, "q")
        said = wait_for(session, "Recording:")
        assert str(record.name) in said
        assert "complete hear_alarm" in Path(record).read_text(encoding="utf-8")
        # the replay command it printed works as printed (opspec run --script)
        joined = tmux("capture-pane", "-p", "-J", "-t", session)   # wrapped lines joined
        printed = next(line for line in joined.splitlines()
                       if line.strip().startswith("or: opspec run"))
        argv = shlex.split(printed.split(":", 1)[1])
        done = subprocess.run([sys.executable, "-m", "opspec.cli", *argv[1:], "--timeline",
                               "none"], capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr
        assert "doses_taken" in done.stdout
    finally:
        subprocess.run(["tmux", "-L", SOCKET, "kill-session", "-t", session],
                       capture_output=True, check=False)


def test_q_quits_at_once_while_a_long_skip_runs(tmp_path):
    session = f"opspec-{uuid.uuid4().hex[:8]}"
    vacuum = SPEC.parent / "vacuum_cleaner.xpdl"
    # a whole day of the robot: a skip to its end takes minutes of engine time
    command = (f"{sys.executable} -m opspec.cli walkthrough {vacuum} --days 1 --no-record; "
               "echo EXIT=$?")
    tmux("new-session", "-d", "-s", session, "-x", "80", "-y", "24")
    try:
        tmux("set-option", "-t", session, "remain-on-exit", "on")
        tmux("send-keys", "-t", session, command, "Enter")
        wait_for(session, "no user lane")
        tmux("send-keys", "-t", session, "u")          # to the end of the day
        wait_for(session, "skipping")
        tmux("send-keys", "-t", session, "q")
        wait_for(session, "EXIT=0", timeout=10.0)      # not after the skip
    finally:
        subprocess.run(["tmux", "-L", SOCKET, "kill-session", "-t", session],
                       capture_output=True, check=False)


def test_large_high_contrast_in_a_small_real_terminal(tmp_path):
    """A big font leaves 64x20 cells: the alarm, the button and the big clock still show."""
    session = f"opspec-{uuid.uuid4().hex[:8]}"
    command = (f"{sys.executable} -m opspec.cli walkthrough {SPEC} --no-record --large "
               "--high-contrast --sound off; echo EXIT=$?")
    tmux("new-session", "-d", "-s", session, "-x", "64", "-y", "20")
    try:
        tmux("set-option", "-t", session, "remain-on-exit", "on")
        tmux("send-keys", "-t", session, command, "Enter")
        wait_for(session, "you perform")
        tmux("send-keys", "-t", session, "u")
        # the alarm, its button and the big digits' bottoms, all on the 64x20 screen at once
        wait_for(session, "THE DEVICE CALLS YOU", "[a] Hear the alarm", "((( RINGING )))",
                 "\u2570\u2500\u256f")
        tmux("send-keys", "-t", session, "a")
        tmux("send-keys", "-t", session, "a")
        tmux("send-keys", "-t", session, "b")
        wait_for(session, "your own action")
        tmux("send-keys", "-t", session, "q")
        wait_for(session, "EXIT=0", timeout=10.0)
    finally:
        subprocess.run(["tmux", "-L", SOCKET, "kill-session", "-t", session],
                       capture_output=True, check=False)
