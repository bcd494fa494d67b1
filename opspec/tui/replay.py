"""Replaying a walkthrough recording: the same offers acted on, so the same trace.

A recording is a script (:mod:`opspec.usermodels.scripts`) whose actions name the workflow
instance they were done in: ``complete hear_alarm #6``. The script language keeps the ``#6``
(``Step.instance``): a tagged step is used only for an offer of instance 6, in a walkthrough's
``--replay`` and in ``opspec run --script`` alike. When three identical "Hear the alarm" offers wait and the person took the
newest, the replay takes the newest too. Recordings written before the tags (plain
``complete hear_alarm``) still replay, matching offers in order as before.

A replay ends where the recorded session ended (:func:`recorded_end`): the person quit at
12:34, so the replay stops at 12:34 instead of running the rest of the day without them.
The script language has no place for that time (a script file holds ``steps`` and
``otherwise``, which ``opspec run --script`` checks), so the trace beside the recording keeps
it: its header says where the run was to end (``until``), and a session the person quit
before then ends with a ``walkthrough.quit`` event (``until``: the second they quit at).

A replay runs the recorded session's seed (:func:`recorded_seed`, the trace header's
``seed``) unless ``--seed`` says otherwise: the device's draws (a duration, a branch) of
another seed are another session, which the recorded actions would not fit.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from opspec.engine.compiled import CompiledPackage
from opspec.usermodels.scripts import ScriptUser, load_script

__all__ = ["QUIT", "instance_tag", "load_recording", "recorded_end", "recorded_seed",
           "refuse_nothing_to_replay", "script_notes", "tagged_action"]

#: the trace event of a session the person quit before the end of its run: ``until``, the
#: simulated second they quit at
QUIT = "walkthrough.quit"

_TAG = re.compile(r"(?:^|\s)#(\d+)(?=\s|$)")


def tagged_action(verb: str, target: str, instance: int | None, rest: str = "") -> str:
    """The recorded action text: ``complete hear_alarm #6`` (``fail take_pill #6 dropped``:
    the tag comes before the exception name, which the script language takes from the last
    plain word)."""
    words = [verb, target]
    if instance is not None:
        words.append(f"#{instance}")
    if rest:
        words.append(rest)
    return " ".join(words)


def instance_tag(action: str) -> int | None:
    """The instance an action names (``#6``), or ``None`` for an untagged action."""
    match = _TAG.search(action)
    return int(match.group(1)) if match else None


def load_recording(path: str | Path, compiled: CompiledPackage | None = None) -> ScriptUser:
    """Read a recording (or any script file) for replay, checking the activities and
    triggers it names against ``compiled`` like ``opspec run --script`` does.

    Raises :class:`~opspec.errors.ConfigurationError` (unreadable file, bad step, a name the
    spec does not have)."""
    if compiled is None:
        return load_script(path).performer()
    from opspec.request import scripted_user

    # each step keeps its "#6" (Step.instance): it acts only on an offer of that instance
    performer: ScriptUser = scripted_user(path, compiled).source.performer()
    return performer


def recorded_end(path: str | Path) -> float | None:
    """Where the session recorded in ``path`` ended, as its trace beside it
    (``REC.trace.jsonl``) says: the second the person quit at (``0.0``: before the clock
    moved, nothing to replay), else the end of its run;
    ``None`` when nothing says so: a recording made before sessions wrote it, any other
    script, a trace gone or not a walkthrough's."""
    try:
        with _trace_of(path).open(encoding="utf-8") as lines:
            header = _walkthrough_header(lines)
            if header is None:
                return None
            end = _seconds(header.get("until"))
            for line in lines:
                if QUIT in line:
                    event = json.loads(line)
                    if isinstance(event, dict) and event.get("kind") == QUIT and isinstance(
                            event.get("data"), dict):
                        quit_at = event["data"].get("until")
                        # quit before the clock moved: 0 s, which no --until can say
                        end = 0.0 if quit_at == 0 and not isinstance(quit_at, bool) else (
                            _seconds(quit_at) or end)
    except (OSError, UnicodeDecodeError, ValueError):
        return None      # unreadable: the replay runs the whole run, as before
    return end


def refuse_nothing_to_replay(path: str | Path, option: str) -> float | None:
    """:func:`recorded_end` of ``path``, refusing a session quit before its clock moved
    (``option``: ``--replay`` or ``--script``, the option that named it): replayed without an
    end of its own, it would run the whole run without the person, which is not the session.

    Raises :class:`~opspec.errors.ConfigurationError`."""
    from opspec.errors import ConfigurationError

    end = recorded_end(path)
    if end == 0.0:
        raise ConfigurationError(
            f"{option} {path}: the session was quit before its clock moved: "
            "there is nothing to replay",
            hint="--until T or --days D replays to then without the person")
    return end


def script_notes(path: str | Path, *, horizon: float, seed: int,
                 end_given: bool) -> list[str]:
    """What a run of the recording ``path`` as a script (``opspec run --script``) does not
    replay of the session, in words: it goes on to ``horizon`` (no ``end_given``: no
    ``--until`` nor ``--days``) where the session ended earlier, or it runs ``seed`` where
    the session ran another (the device's draws of another seed are another session). A
    walkthrough's ``--replay`` takes both from the recording's trace; a script cannot say
    them, so the run does not, and says how to."""
    from opspec.clock import clock_time
    from opspec.tui.summary import until_text

    notes = []
    end = None if end_given else recorded_end(path)
    if end is not None and end != horizon:
        notes.append(f"{path} records a walkthrough that ended at {clock_time(end)}: this "
                     f"run goes on to {clock_time(horizon)} without the person "
                     f"(--until {until_text(end)} ends where the session did)")
    recorded = recorded_seed(path)
    if recorded is not None and recorded != seed:
        notes.append(f"{path} records a walkthrough run with seed {recorded}, this run has "
                     f"seed {seed} (--seed {recorded} replays the session's device draws)")
    return notes


def recorded_seed(path: str | Path) -> int | None:
    """The run seed of the session recorded in ``path``, as its trace beside it
    (``REC.trace.jsonl``) says in its header; ``None`` when nothing says so (as
    :func:`recorded_end`)."""
    from opspec.errors import ConfigurationError
    from opspec.run_rules import check_seed

    try:
        with _trace_of(path).open(encoding="utf-8") as lines:
            header = _walkthrough_header(lines)
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    seed = None if header is None else header.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int):
        return None
    try:
        return check_seed(seed)
    except ConfigurationError:
        return None                     # not a seed any door takes: not one to run


def _trace_of(path: str | Path) -> Path:
    return Path(path).with_suffix(".trace.jsonl")


def _walkthrough_header(lines: Iterator[str]) -> dict[str, Any] | None:
    """The header (the first line) of a walkthrough's trace; ``None`` for another file's."""
    header = json.loads(next(lines, "{}"))
    if not isinstance(header, dict) or header.get("walkthrough") is not True:
        return None
    return header


def _seconds(value: object) -> float | None:
    """A positive number of seconds, or ``None``."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0:
        return float(value)
    return None
