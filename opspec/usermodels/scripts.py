"""Scripted users as plain data: a small, readable script language on the engine's ScriptedUser.

A script is a list of ``(when, action)`` pairs (in Python, in a scenario file or in a script
file for ``opspec run --script``)::

    [("after trg_2 90s", "press_report")]          # report 90 s after the (latest) alarm
    [("never", "press_report")]                    # a user who never reports
    [(90.0, "complete walk_to_dispenser")]         # 90 s after walking is offered
    [("at 08:03", "raise trg_1")]                  # send a message at 08:03 on day 1

**Actions**: ``[VERB] ACTIVITY [key=value ...]``. ``VERB`` is ``complete`` (the default when
omitted), ``choose`` (pick an alternative of a deferred choice; naming the alternative is
enough), ``omit``, ``fail ACTIVITY [EXCEPTION]`` or ``raise TRIGGER``. ``key=value`` words set
data fields on completion (values are read as JSON, else kept as text).

**When** (all times in simulated seconds; durations as in specs: ``90``, ``90s``, ``1m30s``,
``1.5 min``, ``PT90S``):

* ``90`` / ``"90s"`` / ``"+90s"`` - that long after the activity is offered;
* ``"at 3600"``, ``"at 08:01:30"``, ``"at 08:00 on day 2"`` - at that simulated time (an
  offer arriving later acts at once);
* ``"after NAME 90s"`` - 90 s after the latest time trigger ``NAME`` was raised or activity
  ``NAME`` completed, at or before the offer (``after trg_2 90s``: 90 s after the alarm that
  started this episode); if ``NAME`` has not happened yet, counted from the offer;
* ``"each ..."`` - any of the above, reused for every matching offer (steps are otherwise
  used once, in order);
* ``"never"`` - every offer of the activity (or of a choice offering it) is omitted;
* ``"otherwise"`` with action ``complete`` / ``omit`` / ``wait`` - what happens to offers no
  step names (default: ``complete`` at once; a choice then takes its first alternative).

So ``[("after trg_2 90s", "press_report")]`` is a user who hears the alarm, walks and presses
"report" exactly 90 s after the alarm, then takes the pill at once.

A script file is TOML or JSON (told from the content: JSON starts with ``{``, whatever
the file's name) with an optional ``otherwise`` and a ``steps`` list whose
entries are ``[when, action]`` pairs or tables ``{when = "...", do = "..."}``::

    otherwise = "complete"
    steps = [
      ["after trg_2 90s", "press_report"],
      { when = "each 0", do = "complete take_pill" },
    ]
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from opspec.engine.builtin_performers import ScriptedUser, Step
from opspec.engine.performers import WorkItem
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError, SourceLocation
from opspec.files import json_loads
from opspec.toml_lines import located

__all__ = ["DEFAULTS", "Script", "ScriptEntry", "ScriptUser", "load_script", "parse_script",
           "script_format"]

DEFAULTS = ("complete", "omit", "wait")
_VERBS = ("complete", "choose", "omit", "fail", "raise")
_HINT = ("write e.g. (90, 'complete walk_to_dispenser'), ('after trg_2 90s', 'press_report'), "
         "('at 08:03', 'raise trg_1'), ('never', 'press_report') or ('otherwise', 'omit'); "
         "see docs/spec-testing.md")
_DAY = 86_400.0
_PLURAL = {"activity": "activities", "trigger": "triggers", "anchor": "activities and triggers"}

ScriptEntry = tuple[float | str, str]


@dataclass(frozen=True, slots=True)
class _Anchored:
    """A step whose time counts from the latest occurrence of ``anchor``."""

    step: Step
    anchor: str


@dataclass(frozen=True, slots=True)
class Script:
    """A parsed script: engine :class:`Step` values, their anchors and the default.

    ``anchors`` maps step indexes to the trigger or activity name their time counts from.
    ``names`` lists every activity, trigger and anchor name the script uses, so a caller can
    check them against a spec (:meth:`check_names`). Build performers with :meth:`performer`.
    """

    steps: tuple[Step, ...]
    anchors: Mapping[int, str]
    otherwise: str = "complete"
    where: str = "<script>"
    #: where each step is written (a script file's ``file:line: steps[N]``), by step index
    places: tuple[SourceLocation, ...] = ()

    @property
    def names(self) -> dict[str, str]:
        """Name -> what it must be (``activity``, ``trigger`` or ``anchor``)."""
        return {name: what for name, (what, _index) in self._first_uses().items()}

    def _first_uses(self) -> dict[str, tuple[str, int]]:
        """Name -> (what it must be, the index of the first step naming it)."""
        out: dict[str, tuple[str, int]] = {}
        for index, step in enumerate(self.steps):
            out.setdefault(step.target, ("trigger" if step.verb == "raise" else "activity",
                                         index))
            if index in self.anchors:
                out.setdefault(self.anchors[index], ("anchor", index))
        return out

    def place(self, index: int) -> SourceLocation:
        """Where step ``index`` is written (the script itself when that is not known)."""
        return self.places[index] if index < len(self.places) else SourceLocation(self.where)

    def check_names(self, activities: Iterable[str], triggers: Iterable[str]) -> None:
        """Raise :class:`ConfigurationError` for names the spec does not have, at the step
        that names one, with the closest names first and then those it has (a misspelt
        activity would otherwise just never match an offer)."""
        import difflib

        acts, trigs = set(activities), set(triggers)
        for name, (what, index) in self._first_uses().items():
            known = {"activity": acts, "trigger": trigs, "anchor": acts | trigs}[what]
            if name not in known:
                close = difflib.get_close_matches(name, sorted(known), n=3)
                meant = (f" (did you mean {' or '.join(map(repr, close))}?)" if close else "")
                listing = ", ".join(sorted(known)) or "(none)"
                raise ConfigurationError(
                    f"the script names {what} {name!r}, which the spec does not have{meant}",
                    location=self.place(index), hint=f"known {_PLURAL[what]}: {listing}")

    def performer(self) -> ScriptUser:
        """A fresh performer following this script (one per simulated user)."""
        return ScriptUser(self)


class ScriptUser(ScriptedUser):
    """The engine's :class:`ScriptedUser`, plus steps timed from triggers and activities.

    It is also a trace listener (``selects`` trigger raises and activity completions): the
    caller must pass it in the simulation's ``listeners`` for ``after NAME`` steps to see
    their anchors (:func:`opspec.testing.simulation.simulate` does).
    """

    def __init__(self, script: Script) -> None:
        super().__init__(list(script.steps),
                         default="wait" if script.otherwise == "wait" else script.otherwise)
        self.script = script
        self.last_seen: dict[str, float] = {}
        self.selects = frozenset({(EventKind.TRIGGER_RAISED, None, None),
                                  (EventKind.ACTIVITY_COMPLETED, None, None)})

    def __call__(self, event: TraceEvent) -> None:
        if event.kind == EventKind.TRIGGER_RAISED:
            name = event.data.get("name")
            if isinstance(name, str):
                self.last_seen[name] = event.time
        elif event.kind == EventKind.ACTIVITY_COMPLETED and event.activity is not None:
            self.last_seen[event.activity] = event.time

    def offer(self, item: WorkItem) -> None:
        # Anchored steps become concrete (absolute) steps just before the base class picks
        # one, from the original step each time, so ``each`` steps re-anchor per offer.
        for index, anchor in self.script.anchors.items():
            original = self.script.steps[index]
            seen = self.last_seen.get(anchor)
            self.steps[index] = (original if seen is None else
                                 replace(original, delay=seen + original.delay, absolute=True))
        super().offer(item)


def _seconds(text: str, at: SourceLocation) -> float:
    from opspec.clock import parse_duration

    cleaned = text.strip().removeprefix("+").strip()
    try:
        return parse_duration(cleaned, error=ConfigurationError)
    except ConfigurationError as error:
        raise ConfigurationError(f"cannot read the time {text.strip()!r}: {error.message}",
                                 location=at, hint=error.hint) from None


_AT = re.compile(r"(?P<time>.+?)(?:\s+on\s+day\s+(?P<day>\d+))?", re.IGNORECASE)


def _absolute(text: str, at: SourceLocation) -> float:
    from opspec.clock import parse_time_of_day

    match = _AT.fullmatch(text.strip())
    assert match is not None
    clock, day = match["time"].strip(), int(match["day"] or 1)
    if day < 1:
        raise ConfigurationError(f"day {day} does not exist (the first day is day 1)",
                                 location=at, hint=_HINT)
    if ":" in clock:
        return (day - 1) * _DAY + parse_time_of_day(clock, location=at,
                                                     error=ConfigurationError)
    return (day - 1) * _DAY + _seconds(clock, at)


def _entry(when: Any, action: Any, at: SourceLocation
           ) -> tuple[Step | None, str | None, str | None]:
    """One entry -> (step, anchor, otherwise)."""
    if not isinstance(action, str) or not action.split():
        raise ConfigurationError(f"the action {action!r} is not text",
                                 location=at, hint=_HINT)
    if isinstance(when, bool) or not isinstance(when, (int, float, str)):
        raise ConfigurationError(f"the time {when!r} is neither seconds nor text",
                                 location=at, hint=_HINT)
    if isinstance(when, (int, float)):
        if when < 0:
            raise ConfigurationError(f"the time {when!r} is negative",
                                     location=at, hint=_HINT)
        return _step(float(when), action, at), None, None
    text = when.strip()
    words = text.split()
    head = words[0].lower() if words else ""
    if head == "otherwise" and len(words) == 1:
        mode = action.strip().lower()
        if mode not in DEFAULTS:
            raise ConfigurationError(f"'otherwise' takes one of {', '.join(DEFAULTS)}, "
                                     f"not {action!r}", location=at)
        return None, None, mode
    if head == "never" and len(words) == 1:
        target = action.split()
        if len(target) != 1:
            raise ConfigurationError(f"'never' takes one activity name, not {action!r}",
                                     location=at, hint=_HINT)
        return Step("omit", target[0], 0.0, repeat=True), None, None
    repeat = head == "each"
    if repeat:
        text = text[len(words[0]):].strip()
        if not text:
            raise ConfigurationError("'each' needs a time after it ('each 0', 'each after "
                                     "trg_2 90s')", location=at)
    lowered = text.lower()
    if lowered.startswith("after "):
        parts = text.split(None, 2)
        if len(parts) < 3:
            raise ConfigurationError(f"{when!r} needs a name and a time: 'after NAME 90s'",
                                     location=at, hint=_HINT)
        step = _step(_seconds(parts[2], at), action, at, repeat=repeat)
        if step.verb == "raise":
            raise ConfigurationError("a 'raise' step takes an absolute time ('at 08:03'), "
                                     f"not {when!r}", location=at)
        return step, parts[1], None
    if lowered.startswith(("at ", "@")):
        clock = text[1:] if text.startswith("@") else text[3:]
        return _step(_absolute(clock, at), action, at, absolute=True,
                     repeat=repeat), None, None
    return _step(_seconds(text, at), action, at, repeat=repeat), None, None


def _step(delay: float, action: str, at: SourceLocation, *, absolute: bool = False,
          repeat: bool = False) -> Step:
    words = action.split()
    if words[0] not in _VERBS:
        words = ["complete", *words]
    if len(words) < 2:
        raise ConfigurationError(f"the action {action!r} names no activity",
                                 location=at, hint=_HINT)
    text = " ".join(words)
    try:
        step = Step.parse(0.0, text, where=str(at), repeat=repeat)
    except ConfigurationError as error:
        raise ConfigurationError(error.message, location=at, hint=_HINT) from None
    return replace(step, delay=delay, absolute=absolute or step.verb == "raise")


def parse_script(entries: Sequence[Any] | Script, *, where: str = "<script>") -> Script:
    """A :class:`Script` from ``(when, action)`` pairs (see the module docstring).

    Raises :class:`ConfigurationError` naming the entry (``where: steps[N]``) and the fix.
    """
    if isinstance(entries, Script):
        return entries
    return _parsed(entries, where, lambda n: SourceLocation(f"{where}: steps[{n}]"))


def _parsed(entries: Any, where: str, place: Callable[[int], SourceLocation]) -> Script:
    """The script of ``entries``, entry ``n`` written at ``place(n)``."""
    if isinstance(entries, (str, bytes)) or not isinstance(entries, Sequence):
        raise ConfigurationError("a script is a list of (when, action) pairs",
                                 location=SourceLocation(where), hint=_HINT)
    steps: list[Step] = []
    places: list[SourceLocation] = []
    anchors: dict[int, str] = {}
    otherwise = "complete"
    for n, entry in enumerate(entries):
        at = place(n)
        when, action = _pair(entry, at)
        step, anchor, mode = _entry(when, action, at)
        if mode is not None:
            otherwise = mode
            continue
        assert step is not None
        if anchor is not None:
            anchors[len(steps)] = anchor
        steps.append(step)
        places.append(at)
    return Script(tuple(steps), anchors, otherwise, where, tuple(places))


def _pair(entry: Any, at: SourceLocation) -> tuple[Any, Any]:
    if isinstance(entry, Mapping):
        unknown = set(entry) - {"when", "do"}
        if unknown or "do" not in entry:
            raise ConfigurationError(
                "a step table has 'do' (the action) and 'when' (default 0)"
                + (f"; unknown key(s) {', '.join(sorted(unknown))}" if unknown else ""),
                location=at, hint='{ when = "after trg_2 90s", do = '
                '"press_report" }')
        return entry.get("when", 0), entry["do"]
    if isinstance(entry, (list, tuple)) and len(entry) == 2:
        return entry[0], entry[1]
    raise ConfigurationError(f"a step is a (when, action) pair, not {entry!r}",
                             location=at, hint=_HINT)


def script_format(raw: bytes, name: str = "") -> str:
    """``"JSON"`` or ``"TOML"``, told from the content: a JSON script is an object, so it
    starts with ``{`` — which no TOML document can (a walkthrough recorded with
    ``--record session.rec`` replays whatever its name). Otherwise the name decides
    (``.json``: JSON, so a broken JSON file gets JSON's error message), else TOML."""
    head = raw.lstrip(b"\xef\xbb\xbf \t\r\n")
    return "JSON" if head.startswith(b"{") or name.lower().endswith(".json") else "TOML"


def load_script(path: str | Path) -> Script:
    """Read a script file: TOML, or JSON (told from the content, see :func:`script_format`)."""
    from opspec.files import read_bytes, reason
    from opspec.toml_files import parse_toml

    where = str(path)
    try:
        raw = read_bytes(path)            # a pipe or device is refused, never read (blocks)
    except OSError as error:
        raise ConfigurationError(f"cannot read the script: {reason(error)}",
                                 location=SourceLocation(where)) from None
    kind = script_format(raw, where)
    hint = ('a script file is TOML (steps = [...]) or a JSON object ({"steps": [...]}, as '
            "walkthroughs record)")
    text = ""
    try:
        if kind == "TOML":
            text = raw.decode("utf-8")
        document = (json_loads(raw) if kind == "JSON" else   # nesting bounded (opspec.files)
                    parse_toml(text, where=where, what="the script", hint=hint))
    except ValueError as error:        # JSON, or bytes that are not UTF-8
        raise ConfigurationError(f"the script is not valid {kind}: {error}",
                                 location=SourceLocation(where), hint=hint) from None
    if not isinstance(document, dict):
        raise ConfigurationError("a script file is a table with 'steps'",
                                 location=SourceLocation(where))

    def key(name: str) -> SourceLocation:
        # a TOML script's mistakes at their lines (file:line: steps[3]); a JSON one's keys
        return (located(where, name, text.removeprefix("\ufeff")) if kind == "TOML"
                else SourceLocation(where, key=name))

    unknown = set(document) - {"steps", "otherwise"}
    if unknown:
        raise ConfigurationError(f"unknown key(s) {', '.join(sorted(unknown))}",
                                 location=key(min(unknown)),
                                 hint="a script file has 'otherwise' and 'steps'")
    steps = document.get("steps", [])
    if not isinstance(steps, list):
        raise ConfigurationError("'steps' is a list of [when, action] pairs",
                                 location=key("steps"), hint=_HINT)
    script = _parsed(steps, where, lambda n: key(f"steps[{n}]"))
    if "otherwise" in document:
        mode = document["otherwise"]
        if mode not in DEFAULTS:
            raise ConfigurationError(f"'otherwise' takes one of {', '.join(DEFAULTS)}, not "
                                     f"{mode!r}", location=key("otherwise"))
        script = replace(script, otherwise=mode)
    return script
