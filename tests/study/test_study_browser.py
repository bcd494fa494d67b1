"""A study taken part in through a browser: ``opspec study PROTOCOL --serve`` prints one link
per participant; P01 opens theirs in a real headless Chromium and performs their first
session with key presses sent to the page; the recording lands on the researcher's side,
where a terminal session would have put it, and the study counts it done. The same protocol's
sessions performed through Textual's Pilot and the paired comparison of the two designs over
the three participants are tests/study/test_study.py::test_three_participants_two_variants.

Chromium comes from scripts/system-deps.sh (which CI runs); where it is missing the test
runs that script once, and skips only when Chromium still cannot be had.
"""

from __future__ import annotations

import asyncio
import json
import os
import re
import subprocess
import queue
import sys
import threading
from pathlib import Path
from typing import Any

import pytest

from opspec.tui.study import load_protocol

ROOT = Path(__file__).resolve().parents[2]

pytest.importorskip("textual_serve", reason="opspec study --serve needs the study extra: "
                    "pip install 'opspec[study]' (in the test extra)")

from browser_cdp import Browser  # noqa: E402


class Served:
    """``opspec study PROTOCOL --serve --port 0`` as the researcher runs it: its printed
    lines, read as they come (by a thread, so a wait for a line has a bound)."""

    def __init__(self, protocol: Path) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "opspec", "study", str(protocol), "--serve", "--port", "0"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"})
        self.lines: list[str] = []
        self.queue: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.queue.put(line.rstrip("\n"))
        self.queue.put(None)

    def read_until(self, pattern: str, seconds: float = 120.0) -> re.Match[str]:
        """The first line from now on that matches (a bound on the wait, not a timed
        check: the server is expected to say it at once)."""
        while True:
            try:
                line = self.queue.get(timeout=seconds)
            except queue.Empty:
                line = None
            if line is None:
                raise AssertionError(f"the server did not print {pattern!r}:\n"
                                     + "\n".join(self.lines))
            self.lines.append(line)
            found = re.search(pattern, line)
            if found:
                return found

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()


async def _status(url: str) -> int:
    import aiohttp

    async with aiohttp.ClientSession() as http, http.get(url) as response:
        return response.status


#: Installed in the page before its own scripts: reads what the app's websocket sends to
#: the terminal and keeps its last status line -- "d1 08:00:23  60x  running  |  ..." -- as
#: [simulated seconds since the start, state] in ``window.__status``, so that the test
#: sees the walkthrough's state as the person does instead of waiting a fixed time after
#: each key. (The summary that opens at the run's end covers the status line, but the
#: "[ENDED]" state is sent first.)
RECORD_STATUS = r"""
(() => {
  const Native = window.WebSocket;
  const decoder = new TextDecoder();
  // (a loaded machine's clock may fall short of the speed asked: "60x (really 12x)  running")
  const line = /d(\d+) (\d\d):(\d\d):(\d\d)\s+\S+x(?: \(really [^)]*\))?\s+(\[ENDED\]|skipping|running|PAUSED)/g;
  let tail = "";                      // a status line may be cut between two messages
  window.__status = null;
  window.WebSocket = class extends Native {
    constructor(...args) {
      super(...args);
      this.addEventListener("message", (event) => {
        if (typeof event.data === "string") return;
        const text = tail + decoder.decode(event.data, {stream: true});
        for (const [, day, h, m, s, state] of text.matchAll(line)) {
          window.__status = [86400 * (day - 1) + 3600 * h + 60 * m + 1 * s, state];
        }
        tail = text.slice(-200);
      });
    }
  };
})();
"""
STATUS = "window.__status"


async def _skip_to_the_end(page: Browser) -> int:
    """Press "u" (skip until the next call) until the status line says the run ended; each
    next press only once the status line shows the skip done -- the clock moved on by more
    than the run goes in a few seconds at this speed, and no longer "skipping" (a "u" pressed
    during a skip stops it). Returns the number of presses. The bounds are on the loop, not
    a timed check: a press that seems to have done nothing is simply followed by another."""
    await page.wait_for(STATUS, 120)
    for presses in range(40):
        before, state = await page.evaluate(STATUS)
        if state == "[ENDED]":
            return presses
        await page.press("u")
        for _ in range(300):
            now, state = await page.evaluate(STATUS)
            if state == "[ENDED]" or (state != "skipping" and now - before >= 120):
                break
            await asyncio.sleep(0.1)
    raise AssertionError("the run did not end after 40 presses of u")


async def _take_part(chromium: str, link: str) -> dict[str, Any]:
    """P01 in the browser: read the briefing, click into the page, Enter, hand the lane to
    the model ("h", a stand-in for their own presses), skip ahead ("u") until the run's end,
    quit ("q"). Keys are queued in order, so the presses need no timing; each skip is
    pressed once the page shows the last one done (the run of this protocol ends after
    about six of them)."""
    seen: dict[str, Any] = {}
    async with Browser(chromium) as page:
        await page.call("Page.enable")
        await page.call("Page.addScriptToEvaluateOnNewDocument", source=RECORD_STATUS)
        await page.open(link)
        # textual-serve marks the page once the app's first screen arrived
        await page.wait_for("document.body.classList.contains('-first-byte')", 120)
        seen["title"] = await page.evaluate("document.querySelector('.intro div').textContent")
        # a second window on the same link while the session runs gets nothing
        seen["second_window"] = await _status(link)
        await page.click(600, 150)                    # into the page, as a person does
        await page.press("enter")
        await page.press("h")
        seen["skips"] = await _skip_to_the_end(page)
        await page.press("q")
        # the app closes, the session is marked done and textual-serve shows it closed
        seen["closed"] = await page.wait_for(
            "document.body.classList.contains('-closed')", 120)
        seen["unknown_link"] = await _status(re.sub(r"/p/[^/]+$", "/p/not-a-token", link))
    return seen


def test_a_participant_takes_part_in_a_browser(chromium: str, protocol_file: Path) -> None:
    protocol = load_protocol(protocol_file)
    served = Served(protocol_file)
    try:
        served.read_until(r"one link per participant, served on (http://\S+)")
        links = {p: served.read_until(rf"^\s+{p}\s+(http://\S+/p/\S+)\s").group(1)
                 for p in protocol.participants}
        assert len(set(links.values())) == 3                 # one link each
        first = protocol.pending("P01")[0]
        seen = asyncio.run(_take_part(chromium, links["P01"]))
        served.read_until(r"^P01: session A done")
    finally:
        served.stop()
    assert "participant P01" in seen["title"] and "session 1 of 2" in seen["title"]
    assert seen["second_window"] == 409
    assert seen["unknown_link"] == 404
    assert seen["closed"]
    assert seen["skips"] >= 1                       # the page showed the run's end
    # the run reached its end (only then is a session marked done), and the recording is
    # on the researcher's side, where a terminal session puts it
    assert first.done and first.recording.is_file()
    assert json.loads(first.done_marker.read_text(encoding="utf-8"))["participant"] == "P01"
    header = json.loads(first.trace.read_text(encoding="utf-8").splitlines()[0])
    assert header["person"] == "P01"
    # the links stay the same when the server is started again
    saved = json.loads((protocol.recordings / "links.json").read_text(encoding="utf-8"))
    assert {p: f"/p/{t}" for p, t in saved.items()} == {
        p: link[link.index("/p/"):] for p, link in links.items()}

    # the study counts the browser session as done: P01 has only the other variant left
    # (the Pilot sessions and the paired comparison over the three participants are
    # test_study.py::test_three_participants_two_variants; not run a second time here)
    left = protocol.pending("P01")
    assert len(left) == 1 and left[0].variant != first.variant
