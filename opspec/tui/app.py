"""The walkthrough app: a person performs the user lane of a spec while its device runs.

Layout (works in 80×24, grows with the terminal): a status line (simulated clock, speed,
running or paused, who performs the lane); the device panel (what each participant did last,
running workflow instances and the activity each is in, pending deadlines with a countdown);
the person's panel (what can be done now, one key each — also clickable — and a banner when
the device calls, and what the person's last action led to); the timeline (newest first,
filterable by lane). Every state is said in words and symbols, never by colour alone. The
engine is stepped from this app's event loop. When the run ends, a summary opens (the spec's
metrics, the person's response times, where the recording is).

For a lab with older participants: ``large`` lays the screen out for a big terminal font
(the person's panel first and full width, offers as tall bordered buttons, the clock in big
digits; it works down to 60×20 cells), ``high_contrast`` uses white and yellow on black with
heavy borders and no dimmed text, and ``sound`` picks the cue at every alarm
(:mod:`opspec.tui.sound`: the terminal bell, a system sound, or none).
"""

from __future__ import annotations

import string
import time
from collections.abc import Sequence
from typing import Any, ClassVar

from rich.text import Text
from textual import events
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.theme import Theme
from textual.widgets import Digits, Footer, Static

from opspec.engine.lane_labels import lane_labels
from opspec.tui.interrupt import watch_interrupts
from opspec.tui.modals import HELP, HelpScreen, SummaryScreen, help_screen
from opspec.tui.pace import Pace
from opspec.tui.session import WalkSession, clock, time_of_day_shown
from opspec.tui.sound import Cue
from opspec.tui.terminal_size import SizeWarning
from opspec.tui.timeline import HIDDEN, lane_filters, timeline_text

__all__ = ["HELP", "SummaryScreen", "WalkthroughApp"]

SPEEDS = {"1": 1.0, "2": 10.0, "3": 60.0, "4": 600.0}
# the keys that move or hold the clock: nothing to do once the run has ended
_TIME_KEYS = frozenset({"pause", "speed", "wait", "next_event", "until_user"})
# the offers shown: every letter no other action uses (h l n q s u w x are taken), a..f first
OFFER_KEYS = "".join(k for k in string.ascii_lowercase if k not in "hlnqsuwx")
FOOTER_SPACED_WIDTH = 84      # the footer's keys with their padding (tests/tui checks 80 fits)
TICK_S = 0.1
# The engine runs in slices so that keys (q, ctrl+c, space) are read between them: at most
# SLICE_STEPS engine events per slice, and slices for at most SLICE_S of wall time per tick.
SLICE_STEPS = 200
SLICE_S = 0.08
KEY_S = 0.25                  # a key's own jump (w, n) may take a little longer

class FittingFooter(Footer):
    """The footer, its keys closed up on a terminal narrower than the spaced-out footer, so
    that every key stays visible (80 x 24 is the usual lab terminal)."""

    def on_resize(self, event: events.Resize) -> None:
        self.compact = event.size.width < FOOTER_SPACED_WIDTH


HIGH_CONTRAST = Theme(
    name="opspec-high-contrast", dark=True,
    primary="#FFFF00", secondary="#FFFFFF", accent="#00FFFF", warning="#FFFF00",
    error="#FF5555", success="#00FF00", foreground="#FFFFFF", background="#000000",
    surface="#000000", panel="#000000", boost="#333333",
    variables={"footer-key-foreground": "#FFFF00", "footer-description-foreground": "#FFFFFF",
               "block-cursor-background": "#FFFF00", "block-cursor-foreground": "#000000"})
"""White and yellow on black: contrast ratios of 21:1 and 19.6:1 (WCAG AAA asks 7:1)."""


class StatusLine(Static):
    """The clock and controls line; it owns the app's tick timer (so the timer dies with
    the widget and never fires into an unmounted app). The simulated clock advances by the
    wall time that really passed between ticks (a late tick does not slow the clock, so a
    response timed at 1x is the person's real one)."""

    def on_mount(self) -> None:
        self._last = time.monotonic()
        self.set_interval(TICK_S, self._tick)

    def _tick(self) -> None:
        now = time.monotonic()
        # at most one second at once (a suspended terminal does not jump the clock)
        elapsed, self._last = min(1.0, max(0.0, now - self._last)), now
        if self.is_mounted:
            app = self.app
            if isinstance(app, WalkthroughApp):
                app.tick(elapsed)


class OfferLine(Static):
    """One action the person can take; clicking it does it."""

    def __init__(self, index: int, text: Text) -> None:
        super().__init__(text, classes="offer")
        self.index = index

    def on_click(self) -> None:
        app = self.app
        if isinstance(app, WalkthroughApp):
            app.do_offer(self.index)


class WalkthroughApp(App[str | None]):
    """See the module docstring. ``session`` is a :class:`WalkSession`; the app's return
    value is the recording's path (or ``None`` when not recording)."""

    TITLE = "opspec walkthrough"
    ENABLE_COMMAND_PALETTE = False       # the footer's room goes to the walkthrough's keys
    CSS = """
    Screen { layout: vertical; }
    #status { height: 1; background: $primary; color: $text; padding: 0 1; }
    #panels { height: 2fr; min-height: 12; }
    #device, #person { width: 1fr; height: 1fr; border: round $secondary; padding: 0 1; }
    #device { width: 3fr; text-wrap: nowrap; text-overflow: ellipsis; }
    #person { width: 2fr; }
    #person.calling { border: heavy $warning; }
    #offers { height: auto; }
    #aftermath { height: auto; margin-top: 1; text-style: italic; }
    #timeline { height: 1fr; min-height: 5; border: round $secondary; padding: 0 1; }
    #bigclock { display: none; }
    .offer { height: auto; }
    .offer:hover { background: $boost; }

    /* large: laid out for a big terminal font; the person's panel first, full width */
    Screen.large #panels { layout: vertical; height: 3fr; }
    Screen.large #person { width: 1fr; height: 3fr; min-height: 9; }
    Screen.large #device { width: 1fr; height: 1fr; min-height: 4; }
    Screen.large #bigclock { display: block; height: 3; width: auto; }
    Screen.large #timeline { min-height: 3; }
    Screen.large #timeline.hidden { display: none; }
    Screen.large .offer { border: heavy $secondary; padding: 0 1; text-style: bold;
                          margin-bottom: 0; }
    Screen.large #call, Screen.large #aftermath { text-style: bold; }
    Screen.large #aftermath { margin-top: 0; }

    /* high contrast: heavy borders everywhere, nothing dimmed */
    Screen.contrast #device, Screen.contrast #person, Screen.contrast #timeline {
        border: heavy $foreground; }
    Screen.contrast #person.calling { border: double $warning; }
    Screen.contrast #aftermath { text-style: bold; }
    """
    # the footer shows them in this order and cuts at the right: what a participant needs
    # first (pause, help, quit), then the coordinator's time controls
    BINDINGS: ClassVar = [
        Binding("space", "pause", "pause"),
        Binding("question_mark", "help", "help"),
        Binding("q", "quit_walk", "quit"),
        Binding("1", "speed('1')", "speed", key_display="1-4"),
        Binding("2", "speed('2')", "10x", show=False),
        Binding("3", "speed('3')", "60x", show=False),
        Binding("4", "speed('4')", "600x", show=False),
        Binding("w", "wait", "wait 30s"),
        Binding("n", "next_event", "step"),
        Binding("u", "until_user", "until me"),
        Binding("u", "until_user('end')", "to end"),   # nobody to wait for (check_action)
        Binding("h", "hand_over", "model/me"),
        Binding("h", "hand_over('none')", show=False),     # (there: says why not)
        Binding("l", "lane", "lanes", show=False),
        Binding("x", "ignore", "don't", show=False),
        Binding("s", "summary", "summary", show=False),
        Binding("s", "summary('end')", "summary"),         # in the footer once the run ended
        Binding("ctrl+c,ctrl+q", "quit_walk", "quit", show=False, priority=True),
        *[Binding(k, f"offer({i})", show=False) for i, k in enumerate(OFFER_KEYS)],
        # without a letter: the arrows (or Tab, which the screen would take) pick, Enter does
        Binding("down", "select(1)", show=False), Binding("up", "select(-1)", show=False),
        Binding("tab", "select(1)", show=False, priority=True),
        Binding("shift+tab", "select(-1)", show=False, priority=True),
        Binding("enter", "do_selected", show=False),
    ]

    def __init__(self, session: WalkSession, *, title: str = "",
                 notes: Sequence[str] = (), large: bool = False, high_contrast: bool = False,
                 sound: Cue | None = None) -> None:
        super().__init__()
        self.session = session
        self.spec_title = title
        self.notes = list(notes)
        self.large = large
        self.high_contrast = high_contrast
        #: the cue at every alarm (default: the terminal bell)
        self.cue = sound if sound is not None else Cue("bell")
        #: what l cycles through (a spec without a user lane has only "all" to show)
        self.lane_filters = lane_filters(user_lane=session.has_user_lane, large=large)
        self.lane_filter = 0
        #: the timeline's lane column: the spec's lane names, one width for all lines
        self._lanes = lane_labels(session.compiled)
        self._was_calling = False
        self._pace = Pace()                  # the speed the clock really keeps
        self._selected: tuple[int, str | None] | None = None   # the offer Enter does
        #: a SIGINT from outside ended the session (the command exits with status 130)
        self.interrupted = False
        self._release_interrupts = lambda: None
        self._summary_shown = False          # the end-of-run summary opens once
        self._views_ready = False            # set once mounted, cleared when quitting
        #: the line that says so while the terminal is smaller than the layout needs
        self._size_warning = SizeWarning(large=large)
        session.listeners.append(self._on_event)

    # ------------------------------------------------------------------ layout
    def compose(self) -> ComposeResult:
        yield StatusLine(id="status")
        with Horizontal(id="panels"):
            yield Static(id="device")
            with Vertical(id="person"):
                yield Digits("", id="bigclock")
                yield Static(id="call")
                yield Vertical(id="offers")
                yield Static(id="aftermath")
        yield Static(id="timeline")
        yield self._size_warning
        yield FittingFooter()

    def on_mount(self) -> None:
        if self.high_contrast:
            self.register_theme(HIGH_CONTRAST)
            self.theme = HIGH_CONTRAST.name
            self.screen.add_class("contrast")
        if self.large:
            self.screen.add_class("large")
            # the timeline is for the coordinator: hidden until l shows it
            self.lane_filter = self.lane_filters.index(HIDDEN)
            self.query_one("#timeline", Static).add_class("hidden")
            # the person's panel comes first (on top) when the font is big
            panels = self.query_one("#panels", Horizontal)
            panels.move_child(self.query_one("#person"), before=self.query_one("#device"))
        self.query_one("#device", Static).border_title = "Device"
        self.query_one("#person", Vertical).border_title = "You (the user lane)"
        self.query_one("#timeline", Static).border_title = "Timeline (newest first)"
        self._views_ready = True
        self._release_interrupts = watch_interrupts(self._interrupted)
        self._size_warning.fit(self.size)
        self.refresh_views()

    def on_resize(self, event: events.Resize) -> None:
        self._size_warning.fit(event.size)     # (also under the help or the summary)

    def on_unmount(self) -> None:
        self._release_interrupts()

    def _interrupted(self) -> None:
        self.interrupted = True
        self.action_quit_walk()

    # ------------------------------------------------------------------ time
    def tick(self, wall_seconds: float) -> None:
        session = self.session
        before = len(session.offers)
        skipping = session.skipping
        if skipping or session.paused or session.ended:
            self._pace.reset()
            session.advance(wall_seconds, SLICE_STEPS)
            self._go_on_skipping()
        else:
            start = session.now
            self._run_slices(start + wall_seconds * session.speed)
            if session.waiting_for_devices:        # the clock waits for a real answer
                self._pace.reset()
            else:
                self._pace.ran(wall_seconds, session.now - start, session.speed)
        if not session.paused or skipping or len(session.offers) != before:
            self.refresh_views()

    def _go_on_skipping(self) -> None:
        """More slices of a skip in progress, for at most SLICE_S of wall time."""
        session = self.session
        deadline = time.monotonic() + SLICE_S
        while (session.skipping and not session.waiting_for_devices
               and time.monotonic() < deadline):
            session.advance(0.0, SLICE_STEPS)

    def _run_slices(self, target: float, seconds: float | None = None) -> None:
        """Step towards simulated ``target`` for at most ``seconds`` (SLICE_S) of wall time
        (the clock falls behind the speed asked rather than the keys going unread)."""
        # (SLICE_S read at the call, not bound as a default when the module loaded)
        deadline = time.monotonic() + (SLICE_S if seconds is None else seconds)
        while not self.session.run_to(target, SLICE_STEPS) and time.monotonic() < deadline:
            pass

    def _on_event(self, event: Any) -> None:
        # ring where the terminal can: at every alarm the device sounds (the board has
        # already seen the event), and when a device that does not signal starts calling
        session = self.session
        calling = session.calling
        alarm = (event.kind == "trigger.raised" and event.lane != "user"
                 and session.device_signals and session.board.ringing)
        if alarm or (calling and not self._was_calling and not session.device_signals):
            self.cue.play(self)
        self._was_calling = calling

    # ------------------------------------------------------------------ actions
    def action_pause(self) -> None:
        self.session.paused = not self.session.paused
        self.refresh_views()

    def action_speed(self, key: str) -> None:
        self.session.speed = SPEEDS[key]
        self.refresh_views()

    def action_wait(self) -> None:
        self.session.spoil_timing("waited 30 s with w")
        self._run_slices(self.session.now + 30.0, KEY_S)
        self.refresh_views()

    def action_next_event(self) -> None:
        self.session.skip_to_next_event(SLICE_STEPS)
        self.refresh_views()

    def action_until_user(self, _shown: str = "") -> None:
        if self.session.skipping:           # pressed again: stop where it is
            self.session.cancel_skip()
        else:
            self.session.skip_until_user(SLICE_STEPS)
            self._go_on_skipping()
        self.refresh_views()

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """The footer's keys as they work in this session: in a replay, or for a spec
        without a user lane, nothing will need the person (u runs "to the end") and nothing
        can be handed over (h is left out of the footer; pressed, it says why). Once the run
        has ended the clock has nowhere to go: the time keys leave the footer (they did
        nothing), and the summary comes into it."""
        ended = self.session.ended
        if action in _TIME_KEYS and ended:
            return False
        if action == "summary":
            return ended == bool(parameters)      # the binding with a parameter: the end
        if action in ("until_user", "hand_over"):
            lane = self.session.has_user_lane and not self.session.replaying and not (
                ended and action == "hand_over")
            return lane != bool(parameters)       # the binding with a parameter: no lane
        return True

    def action_hand_over(self, _shown: str = "") -> None:
        if self.session.ended:
            self.notify("The run has ended: there is nothing to hand over (q quits).",
                        severity="warning")
        elif not self.session.has_user_lane:   # a user model would have nothing to do
            self.notify("This spec has no user lane: there is nothing to hand over.",
                        severity="warning")
        elif self.session.replaying:
            self.notify("The recording performs your lane: there is nothing to hand over.",
                        severity="warning")
        elif self.session.handed_over:
            self.session.take_back()
            self.notify("You perform the user lane again.")
        elif self.session.hand_over():
            self.notify("The user model performs your lane; press h to take it back.")
        else:
            self.notify("No user model: start with --user-model FILE|PRESET.",
                        severity="warning")
        self.refresh_views()

    def action_lane(self) -> None:
        # large: all, device, user, hidden (the big font leaves little room for it)
        if len(self.lane_filters) == 1:
            self.notify("This spec has no user lane: the timeline shows all its events.")
            return
        self.lane_filter = (self.lane_filter + 1) % len(self.lane_filters)
        self.query_one("#timeline", Static).set_class(
            self.lane_filters[self.lane_filter] == HIDDEN, "hidden")
        self.refresh_views()

    def action_offer(self, index: int) -> None:
        self.do_offer(index)

    def do_offer(self, index: int) -> None:
        offers = self.session.offers
        if 0 <= index < len(offers):
            self.session.act(offers[index])
            self.refresh_views()

    def _shown_offers(self) -> list[Any]:
        return self.session.offers[:len(OFFER_KEYS)] if self.session.person_performs else []

    def action_select(self, step: int) -> None:
        offers = [(o.item.key, o.choice) for o in self._shown_offers()]
        if not offers or isinstance(self.screen, ModalScreen):   # the help, the summary
            return
        at = offers.index(self._selected) if self._selected in offers else -1 if step > 0 else 0
        self._selected = offers[(at + step) % len(offers)]
        self.refresh_views()

    def action_do_selected(self) -> None:
        offers = [(o.item.key, o.choice) for o in self._shown_offers()]
        if self._selected in offers and not isinstance(self.screen, ModalScreen):
            self.do_offer(offers.index(self._selected))

    def action_ignore(self) -> None:
        if self.session.offers:
            self.session.ignore(self.session.offers[0])
            self.refresh_views()

    def action_help(self) -> None:
        self._push_paused(help_screen(self.session, large=self.large))

    def action_summary(self, _shown: str = "") -> None:
        if not isinstance(self.screen, SummaryScreen):
            self._open_summary()

    def _open_summary(self) -> None:
        session = self.session
        self._push_paused(SummaryScreen(session.summary_lines(final=session.ended)))

    def _push_paused(self, screen: ModalScreen[None]) -> None:
        """Show ``screen`` over the app: the clock stands still while the person reads it,
        and resumes as it was when it closes."""
        was_paused = self.session.paused
        self.session.paused = True

        def resume(_result: None) -> None:
            self.session.paused = was_paused
            self.refresh_views()

        self.push_screen(screen, resume)

    def action_quit_walk(self) -> None:
        self._release_interrupts()
        self._views_ready = False
        self.cue.close()
        self.session.close()
        path = self.session.record_path
        self.exit(str(path) if path is not None else None)

    # ------------------------------------------------------------------ views
    def refresh_views(self) -> None:
        if not self._views_ready:
            return
        session = self.session
        summary = False
        if session.ended and not self._summary_shown:
            self._summary_shown = True           # once: the end of the run in words
            summary = not isinstance(self.screen, HelpScreen)
            self.refresh_bindings()              # the footer's keys after the end
        # the state comes first: the line is cut at the right in a narrow terminal
        state = ("[ENDED]" if session.ended
                 else "[waiting for the device]" if session.waiting_for_devices
                 else "skipping... (u: stop)" if session.skipping
                 else session.paused_words if session.paused else "running")
        who = ("no user lane" if not session.has_user_lane      # (a replay of it performs none)
               else "replaying the recording" if session.replaying
               else "model performs your lane" if session.handed_over
               else "you perform the lane")
        pace = self._pace.shown() if state == "running" else ""
        if session.call_mode and state == "running":
            # the call goes on after the alarm stopped, until nothing waits for the person
            state = ("running in real time: the device calls" if session.calling
                     else "running in real time while something waits for you")
        self.query_one("#status", Static).update(Text(
            f"{clock(session.now)}  {session.speed:g}x{pace}  {state}  |  {who}  |  "
            f"{self.spec_title}", no_wrap=True, overflow="ellipsis"))
        if self.large:
            self.query_one("#bigclock", Digits).update(time_of_day_shown(session.now)[:5])
        self.query_one("#device", Static).update(self._device_text())
        person = self.query_one("#person", Vertical)
        call = self.query_one("#call", Static)
        # a run that has ended calls nobody (its alarm was ringing when it ended)
        if session.calling and not session.ended:
            person.add_class("calling")
            banner = Text("(!) THE DEVICE CALLS YOU", style="bold reverse")
            idle = self._idle_text()
            if idle and not self._shown_offers():
                # the alarm rings on after the person let it pass (x), before their lane
                # offers anything, or for the recording to answer: say what now, not a blank
                banner.append("\n" + idle)
            call.update(banner)
        else:
            person.remove_class("calling")
            call.update(self._idle_text())
        box = self.query_one("#offers", Vertical)
        box.remove_children()
        if session.ended:
            pass                                # nothing can be done any more
        elif session.handed_over:
            box.mount(Static("The user model is performing. Press h to take over."))
        else:
            lines: list[Static] = []
            offers = session.offers
            labels = [o.label for o in offers]
            for n, offer in enumerate(offers[:len(OFFER_KEYS)]):
                line = Text()
                line.append(f"[{OFFER_KEYS[n]}]", style="bold reverse")
                line.append(f" {offer.label}")
                if labels.count(offer.label) > 1:      # tell identical offers apart
                    line.append(f" #{offer.item.instance}",
                                style="" if self.high_contrast else "dim")
                if (offer.item.key, offer.choice) == self._selected:
                    line.append("  <- Enter", style="bold")
                lines.append(OfferLine(n, line))
            more = len(offers) - len(OFFER_KEYS)
            if more > 0:
                lines.append(Static(f"(+{more} more: x passes on the first)"))
            if lines:
                box.mount(*lines)
        self.query_one("#aftermath", Static).update(
            Text(session.aftermath.text()) if session.person_performs or session.ended
            else Text())
        timeline = self.query_one("#timeline", Static)
        timeline.update(timeline_text(
            session.events, self._lanes, self.lane_filters[self.lane_filter],
            # as many events as the box holds (it grows with the terminal)
            max(3, timeline.content_size.height - 1), filters=self.lane_filters,
            dim="" if self.high_contrast else "dim"))
        if summary:
            # after the frame that shows [ENDED] on the status line: pushed in this same
            # refresh, the summary could cover the line before it was ever drawn, and a
            # screen reader or a browser page following the status line missed the end
            self.call_after_refresh(self._open_summary)

    def _idle_text(self) -> str:
        """The person's panel when the device is not calling: one line saying what now."""
        session = self.session
        if session.ended:
            # a replay, or a session run with --no-record, wrote no recording to keep
            if session.replaying:
                return "(the replay has ended: q quits; a replay records nothing)"
            if session.record_path is None:
                return "(the run has ended: q quits; nothing was recorded)"
            return "(the run has ended: q quits, the recording is kept)"
        if not session.has_user_lane:          # (replayed too: there is no lane to perform)
            return "(this spec has no user lane: watch the device; u skips to the end)"
        if session.replaying:
            return "(the recording performs your lane: watch, or press u / n to move on)"
        if session.handed_over or session.offers:
            return ""
        return "(nothing to do now: press u to skip until something needs you)"

    def _device_text(self) -> Text:
        session = self.session
        text = Text(no_wrap=True, overflow="ellipsis")
        rows = session.board.rows()
        deadlines = Text()
        # an ended run has no countdown left; what rang then is the state it ended in
        for (instance, activity), due in ([] if session.ended else sorted(
                session.deadlines.items(), key=lambda kv: kv[1])[:3]):
            left = max(0.0, due - session.now)
            deadlines.append(f"deadline {activity} (#{instance}) in {int(left // 60):02d}:"
                             f"{int(left % 60):02d}\n", style="bold")
        if self.large:
            # little room (a big font, 80 x 24 leaves the panel four lines): what is running
            # out first, the countdowns, then what calls for attention, then the rest
            rows.sort(key=lambda row: not row.alert)
            text.append_text(deadlines)
        for row in rows:
            marker = "(x)" if row.status.startswith("FAULT") else "(!)" if row.alert else " * "
            line = Text(no_wrap=True, overflow="ellipsis")
            line.append(f"{marker} {row.shown or row.id}: ", style="bold")
            if session.ended and row.alert:
                line.append("at the end: ")
            line.append(row.status, style="bold reverse" if row.alert else "")
            text.append_text(line)
            text.append("\n")
            if row.detail:
                text.append(f"      {row.detail}\n", style="italic")
        if session.current:
            text.append("Running when the run ended:\n" if session.ended else "Running:\n",
                        style="bold")
            running = sorted(session.current.items())
            for instance, (process, activity) in running[:4]:
                text.append(f"  {process}#{instance} at {activity}\n")
            if len(running) > 4:
                text.append(f"  (+{len(running) - 4} more)\n")
        if not self.large:
            text.append_text(deadlines)
        for note in self.notes:
            if note not in session.board.notes_seen:   # traced notes are on the participants
                text.append(f"note: {note}\n")
        if not text.plain:
            text.append("(idle)")
        return text
