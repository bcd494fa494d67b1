"""Replaying a walkthrough recording: the same offers acted on, so the same trace.

A recording is a script (:mod:`opspec.testing.script`) whose actions name the workflow
instance they were done in: ``complete hear_alarm #6``. The script language reads the
``#6`` word and ignores it (``opspec run --script`` accepts the file as it is, matching offers
in order); :class:`ReplayUser` also honours it: a step tagged ``#6`` is used only for an offer
of instance 6. When three identical "Hear the alarm" offers wait and the person took the
newest, the replay takes the newest too. Recordings written before the tags (plain
``complete hear_alarm``) still replay, matching offers in order as before.
"""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from opspec.engine.compiled import CompiledPackage
from opspec.engine.performers import WorkItem
from opspec.testing.script import Script, ScriptUser, load_script

__all__ = ["ReplayUser", "instance_tag", "load_recording", "tagged_action"]

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


class ReplayUser(ScriptUser):
    """A :class:`ScriptUser` whose tagged steps act only on offers of their instance.

    ``instances`` maps step indexes (as in ``script.steps``) to the instance their action
    was done in; untagged steps match any offer, in order, as in a plain script.
    """

    def __init__(self, script: Script, instances: Mapping[int, int]) -> None:
        super().__init__(script)
        self.instances = dict(instances)

    def offer(self, item: WorkItem) -> None:
        # steps tagged with another instance are hidden from this offer (marked used for
        # the base class's search), then given back
        others = {index for index, instance in self.instances.items()
                  if instance != item.instance} - self._used
        self._used |= others
        try:
            super().offer(item)
        finally:
            self._used -= others


def load_recording(path: str | Path, compiled: CompiledPackage | None = None) -> ReplayUser:
    """Read a recording (or any script file) for replay, checking the activities and
    triggers it names against ``compiled`` like ``opspec run --script`` does.

    Raises :class:`~opspec.errors.ConfigurationError` (unreadable file, bad step, a name the
    spec does not have)."""
    script = load_script(path)
    if compiled is not None:
        activities, triggers = _spec_names(compiled)
        script.check_names(activities, triggers)
    return ReplayUser(script, _tags(path))


def _tags(path: str | Path) -> dict[int, int]:
    """Step index -> instance, read from the raw file (``load_script`` already checked it)."""
    raw = Path(path).read_bytes()
    document: Any = (json.loads(raw) if str(path).endswith(".json")
                     else tomllib.loads(raw.decode("utf-8")))
    out: dict[int, int] = {}
    index = 0
    for entry in document.get("steps", []):
        if isinstance(entry, Mapping):
            when, action = entry.get("when", 0), entry.get("do", "")
        else:
            when, action = entry[0], entry[1]
        if isinstance(when, str) and when.strip().lower() == "otherwise":
            continue                      # sets the default; not a step
        instance = instance_tag(str(action))
        if instance is not None:
            out[index] = instance
        index += 1
    return out


def _spec_names(compiled: CompiledPackage) -> tuple[list[str], list[str]]:
    from opspec.engine.lanes import all_activities

    activities = list(all_activities(compiled))
    triggers: set[str] = set()
    for act in activities:
        for trig in (act.raises, act.trigger, act.start_trigger, act.end_trigger):
            if trig is not None and trig.name:
                triggers.add(trig.name)
    for process in compiled.processes.values():
        for trig in (process.start_trigger, process.end_trigger):
            if trig is not None and trig.name:
                triggers.add(trig.name)
    return [a.id for a in activities], sorted(triggers)

