"""Replaying a walkthrough recording: the same offers acted on, so the same trace.

A recording is a script (:mod:`opspec.usermodels.scripts`) whose actions name the workflow
instance they were done in: ``complete hear_alarm #6``. The script language keeps the ``#6``
(``Step.instance``): a tagged step is used only for an offer of instance 6, in a walkthrough's
``--replay`` and in ``opspec run --script`` alike. When three identical "Hear the alarm" offers wait and the person took the
newest, the replay takes the newest too. Recordings written before the tags (plain
``complete hear_alarm``) still replay, matching offers in order as before.
"""

from __future__ import annotations

import re
from pathlib import Path

from opspec.engine.compiled import CompiledPackage
from opspec.usermodels.scripts import ScriptUser, load_script

__all__ = ["instance_tag", "load_recording", "tagged_action"]

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
