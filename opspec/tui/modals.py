"""The walkthrough's two screens over the session: the help (``?``: its keys) and the
summary (``s``, and by itself at the end of the run). Both stop the clock while open
(:class:`opspec.tui.app.WalkthroughApp` pushes them paused), say in their frame how to close
them, and scroll with the arrow keys where they do not fit (at 80 x 24 neither does). The
help is written for the width of its box: narrower than its 72 columns (``--large`` at 64),
its lines are wrapped with each key's text under its text, never under the keys.

The help is the session's own (:func:`help_text`): it lists only the keys that do something
in it (a replay, or a spec without a user lane, has nothing to answer and nothing to hand
over), says what a replay lets the person do, what the clock does when the device calls, and
what quitting keeps: a recording when it records, nothing in a replay or with
``--no-record``."""

from __future__ import annotations

import textwrap
from collections.abc import Callable, Sequence
from typing import Any, ClassVar

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

from opspec.tui.session_clock import clock

__all__ = ["CLOSE_HELP", "CLOSE_SUMMARY", "HELP", "HelpScreen", "SummaryScreen",
           "help_screen", "help_text", "session_help"]

_KEYS = "[b]opspec walkthrough — keys[/b]"
# the help's lines are at most this wide: its box is 72 columns less border and padding,
# and less the scrollbar on a terminal too short for it (tests/tui/test_help_fits.py)
_WIDTH = 62
_BOX = 72
# the box's border and padding, and the scrollbar a terminal too short for the help shows
_FRAME = 2 + 4 + 2


def help_text(*, replaying: bool = False, recording: bool = True, user_lane: bool = True,
              model: bool = True, on_call: str = "realtime", large: bool = False,
              ends_at: str = "", width: int = _WIDTH, ended: bool = False) -> str:
    """The help for a session, listing only the keys that do something in it: a replay
    (``replaying``; the recording performs the lane, ending at ``ends_at``) and a spec
    without a user lane (``user_lane``) have no actions to answer, and hand nothing over; a
    session without a user ``model`` has nobody to hand the lane to. What quitting keeps and
    whether an omission is recorded are said as they are (a replay and ``--no-record``
    record nothing), and what the clock does when the device calls (``on_call``) as this
    session does it (a replay is never slowed down). ``width``: the widest line, in cells
    (at most 62: the help's box on a terminal of 80 columns or more). Once the run has
    ``ended`` only the timeline, the summary, the help and quitting are left."""
    if ended:
        return _help_after_the_end(kept="a replay records nothing" if replaying
                                   else "the recording is kept" if recording
                                   else "nothing is recorded",
                                   user_lane=user_lane, large=large, width=width)
    person = user_lane and not replaying
    kept = ("a replay records nothing" if replaying
            else "the recording is kept" if recording else "nothing is recorded")
    keys: list[tuple[str, str]] = []
    if person:
        keys += [("[b]a[/b] [b]b[/b] [b]c[/b]…",
                  "do the action shown next to its letter (or click it)"),
                 ("[b]x[/b]", "do not do the first action (an omission"
                  + (", recorded)" if recording else ")")),
                 ("[b]↑↓[/b] [b]enter[/b]", "pick an action, then do it (tab picks too)")]
    keys += [("[b]space[/b]", "pause / resume the clock"),
             ("[b]1 2 3 4[/b]", "speed: real time, 10x, 60x, 600x"),
             ("[b]w[/b]", "let 30 simulated seconds pass"),
             ("[b]n[/b]", "step: skip to the next event"),
             ("[b]u[/b]", "skip until something new needs you (again: stop)" if person
              else "skip to the end of the "
              + ("replay" if replaying else "run") + " (again: stop)")]
    if person and model:
        keys.append(("[b]h[/b]", "hand your lane to the user model / take it back"))
    if user_lane:
        keys.append(("[b]l[/b]", "timeline: all lanes / device / user"
                     + (" / hidden" if large else "")))
    elif large:                      # (without a user lane there is no lane to pick)
        keys.append(("[b]l[/b]", "timeline: shown / hidden"))
    keys += [("[b]s[/b]", "the summary so far (metrics, your response times)" if person
              else "the summary so far (the spec's metrics)"),
             ("[b]?[/b]", "this help (the clock stops while it is open)"),
             ("[b]q[/b], [b]ctrl+c[/b], [b]ctrl+q[/b]", f"quit ({kept})")]
    lines = _key_lines(keys, width)
    paragraphs = []
    if replaying:
        paragraphs.append(
            "This is a replay: " + ("the recording performs your lane" if user_lane
                                    else "this spec has no user lane")
            + ", so nothing waits for your answer. Watch it, pause it, change its speed or "
            "skip ahead (w, n, u); it is never slowed down when the device calls, and it "
            "ends at "
            f"{ends_at or 'the end of its run'}.")
    elif not user_lane:
        paragraphs.append("This spec has no user lane: nothing waits for your answer; "
                          "watch the device.")
    else:
        paragraphs.append({
            "realtime": "When the device calls you, the clock drops to real time and "
                        "comes back when the call is over" + (
                            " (never while the user model performs your lane)."
                            if model else "."),
            "pause": "When the device calls you, the clock pauses (space resumes it).",
            "keep": "When the device calls you, the clock keeps its speed.",
        }.get(on_call, ""))
    paragraphs.append("Device panel: (!) an alert (a ringing alarm), (x) a device fault, "
                      "> what a participant is doing now.")
    for paragraph in paragraphs:
        if paragraph:
            lines += ["", *textwrap.wrap(paragraph, width)]
    return "\n".join([*lines, "", "Press escape or ? to close."])


def _help_after_the_end(*, kept: str, user_lane: bool, large: bool, width: int) -> str:
    """The help once the run has ended: the clock has nowhere to go, nothing is offered."""
    keys = [("[b]s[/b]", "the summary of the run")]
    if user_lane:
        keys.append(("[b]l[/b]", "timeline: all lanes / device / user"
                     + (" / hidden" if large else "")))
    elif large:
        keys.append(("[b]l[/b]", "timeline: shown / hidden"))
    keys += [("[b]?[/b]", "this help"),
             ("[b]q[/b], [b]ctrl+c[/b], [b]ctrl+q[/b]", f"quit ({kept})")]
    return "\n".join([*_key_lines(keys, width), "", *textwrap.wrap(
        "The run has ended: nothing happens any more, so the keys that move the clock or "
        "answer the device do nothing.", width), "", "Press escape or ? to close."])


def _key_lines(keys: Sequence[tuple[str, str]], width: int) -> list[str]:
    """The help's heading and its keys, each key's text wrapped under its text."""
    lines = [_KEYS, ""]
    for key, does in keys:
        shown = Text.from_markup(key).cell_len
        # the key column is 8 wide; a wider key runs into its text after one space
        lead = f"  {key}{' ' * max(1, 8 - shown)}"
        first, *more = textwrap.wrap(does, max(12, width - 2 - max(8, shown + 1))) or [""]
        lines.append(lead + first)
        # under the key's text: a word wrapped under the keys would read as a key
        lines += [" " * (2 + max(8, shown + 1)) + line for line in more]
    return lines


def session_help(session: Any, *, large: bool = False, width: int = _WIDTH) -> str:
    """:func:`help_text` for ``session`` (a :class:`~opspec.tui.session.WalkSession`) as it
    is; ``large``: the app's ``--large`` layout; ``width``: its widest line."""
    return help_text(
        replaying=session.replaying, recording=session.record_path is not None,
        user_lane=session.has_user_lane, model=session.model_factory is not None,
        on_call=session.on_call, large=large, ends_at=clock(session.horizon), width=width,
        ended=session.ended)


def help_screen(session: Any, *, large: bool = False) -> HelpScreen:
    """The help screen of ``session``: :func:`session_help`, written for the width the
    terminal gives it."""
    return HelpScreen(lambda width: session_help(session, large=large, width=width))


#: the help of a recorded session with every key (a user lane, a user model)
HELP = help_text()
# In the frame of the help and the summary, so that it shows however little of them fits
# (at 80 x 24 neither fits whole; the arrow keys scroll them).
CLOSE_HELP = "escape or ?: close  q: quit  arrows: scroll"
CLOSE_SUMMARY = "escape: close  q: quit  arrows: scroll"


class HelpScreen(ModalScreen[None]):
    BINDINGS: ClassVar = [Binding("escape,question_mark", "dismiss", "close"),
                          Binding("q", "app.quit_walk", "quit")]
    DEFAULT_CSS = """
    HelpScreen { align: center middle; }
    HelpScreen > VerticalScroll { width: 72; max-width: 100%; height: auto;
                                  max-height: 100%; border: heavy $accent; padding: 1 2;
                                  background: $surface; }
    """

    def __init__(self, text: str | Callable[[int], str] = HELP) -> None:
        """``text``: the help, or what writes it for a width (the widest line, in cells):
        then it is rewritten whenever the terminal's width changes."""
        super().__init__()
        self._write = None if isinstance(text, str) else text
        self._width = _WIDTH
        self.text = text if isinstance(text, str) else text(_WIDTH)

    def compose(self) -> ComposeResult:
        with VerticalScroll() as frame:
            frame.border_subtitle = CLOSE_HELP
            yield Static(self.text, id="help-text")

    def on_mount(self) -> None:
        self._fit()

    def on_resize(self) -> None:
        self._fit()

    def _fit(self) -> None:
        # Textual would wrap a line too wide for the box at its first column: "click it)"
        # under the keys, as if it were one
        width = max(20, min(_WIDTH, min(_BOX, self.app.size.width) - _FRAME))
        if self._write is None or width == self._width:
            return
        self._width = width
        self.text = self._write(width)
        self.query_one("#help-text", Static).update(self.text)


class SummaryScreen(ModalScreen[None]):
    """The summary: at the end of the run (it opens by itself), or so far (``s``)."""

    BINDINGS: ClassVar = [Binding("escape,s,space", "dismiss", "close"),
                          Binding("q", "app.quit_walk", "quit")]
    DEFAULT_CSS = """
    SummaryScreen { align: center middle; }
    SummaryScreen > VerticalScroll { width: 100; max-width: 100%; height: auto;
                                     max-height: 100%; border: heavy $accent; padding: 0 1;
                                     background: $surface; }
    """

    def __init__(self, lines: Sequence[str]) -> None:
        super().__init__()
        self.lines = list(lines)

    def compose(self) -> ComposeResult:
        with VerticalScroll() as frame:
            frame.border_subtitle = CLOSE_SUMMARY
            yield Static(Text("\n".join([*self.lines, "", "q: quit   escape: close"])),
                         id="summary-text")
