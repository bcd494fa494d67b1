"""The walkthrough's two screens over the session: the help (``?``: every key) and the
summary (``s``, and by itself at the end of the run). Both stop the clock while open
(:class:`opspec.tui.app.WalkthroughApp` pushes them paused), say in their frame how to close
them, and scroll with the arrow keys where they do not fit (at 80 x 24 neither does).

The help says what the session shown keeps (:func:`help_text`): a recording when it records,
nothing in a replay or with ``--no-record``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

__all__ = ["CLOSE_HELP", "CLOSE_SUMMARY", "HELP", "HelpScreen", "SummaryScreen",
           "help_text"]

_HELP = """\
[b]opspec walkthrough — keys[/b]

  [b]a[/b]–[b]z[/b]     do the action shown next to the letter (or click it)
  [b]x[/b]       do not do the first action (an omission{recorded})
  [b]↑↓[/b] [b]enter[/b] pick an action, then do it (tab picks too)
  [b]space[/b]   pause / resume the clock
  [b]1 2 3 4[/b] speed: real time, 10x, 60x, 600x
  [b]w[/b]       let 30 simulated seconds pass
  [b]n[/b]       step: skip to the next event
  [b]u[/b]       skip until something new needs you (again: stop)
  [b]h[/b]       hand your lane to the user model / take it back
  [b]l[/b]       timeline: all lanes / device / user
          (/ hidden, with --large)
  [b]s[/b]       the summary so far (metrics, your response times)
  [b]?[/b]       this help (the clock stops while it is open)
  [b]q[/b], [b]ctrl+c[/b], [b]ctrl+q[/b] quit ({kept})

When the device calls you, the clock drops to real time (or
pauses, with --on-call pause) and comes back when the call is
over.

Device panel: (!) an alert (a ringing alarm), (x) a device
fault, > what a participant is doing now.

Press escape or ? to close."""


def help_text(*, replaying: bool = False, recording: bool = True) -> str:
    """The help for a session: what quitting keeps, and whether an omission is recorded,
    are said as they are for it (a replay and ``--no-record`` record nothing)."""
    kept = ("a replay records nothing" if replaying
            else "the recording is kept" if recording else "nothing is recorded")
    return _HELP.format(kept=kept, recorded=", recorded" if recording and not replaying
                        else "")


#: the help of a recorded session
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

    def __init__(self, text: str = HELP) -> None:
        super().__init__()
        self.text = text

    def compose(self) -> ComposeResult:
        with VerticalScroll() as frame:
            frame.border_subtitle = CLOSE_HELP
            yield Static(self.text, id="help-text")


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
