"""Subjects: what a property counts - completions of an activity, raises of a trigger, starts
of a process - and the tokens of the property language's text form.

A subject is an activity id, a trigger name or a process id, resolved against the spec's
names by :meth:`Subject.bind`; it may be made explicit: ``activity:dispense`` or
``activity dispense``, ``trigger:trg_2``, ``process:notify_workflow``; ``a|b`` means either.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Protocol

from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError

__all__ = ["Names", "Selector", "Selects", "Subject", "parse_subject", "read_subject",
           "spell", "split_words"]

Selects = frozenset[tuple[str, str | None, str | None]]

_TOKEN = re.compile(r"==|!=|<=|>=|<|>|\[|\]|,|\||[^\s=!<>\[\],|]+|\S")


def split_words(text: str) -> list[str]:
    """The words and operators of a property's (or a subject's) text form."""
    return _TOKEN.findall(text)


class Names(Protocol):
    """The names a spec defines (:class:`opspec.engine.names.SpecNames` is one)."""

    @property
    def activities(self) -> tuple[str, ...]: ...
    @property
    def triggers(self) -> tuple[str, ...]: ...
    @property
    def processes(self) -> tuple[str, ...]: ...


class Selector(Protocol):
    """Anything that picks events: a :class:`Subject`, or a predicate's ``Match`` (which
    may test any field); ``str()`` names it in messages."""

    def matches(self, event: TraceEvent) -> bool: ...



def spell(selector: Selector) -> str:
    """The text form of what a property counts: a subject's spelling, else its ``str()``."""
    return selector.spelling() if isinstance(selector, Subject) else str(selector)


@dataclass(frozen=True, slots=True)
class Subject:
    """What a property counts: completions of an activity, raises of a trigger, starts of a
    process; ``what`` is ``None`` until resolved (then any of the three match).
    ``alternatives`` holds the others of ``a|b``."""

    name: str
    what: str | None = None
    alternatives: tuple[Subject, ...] = ()

    def __str__(self) -> str:
        own = f"{self.what} {self.name}" if self.what else self.name
        return " or ".join([own, *map(str, self.alternatives)])

    def matches(self, event: TraceEvent) -> bool:
        if self._own(event):
            return True
        return any(alt.matches(event) for alt in self.alternatives)

    def _own(self, event: TraceEvent) -> bool:
        what, kind = self.what, event.kind
        if kind == EventKind.ACTIVITY_COMPLETED:
            return what in (None, "activity") and event.activity == self.name
        if kind == EventKind.TRIGGER_RAISED:
            return what in (None, "trigger") and event.data.get("name") == self.name
        if kind == EventKind.PROCESS_STARTED:
            return what in (None, "process") and event.process == self.name
        return False

    @property
    def selects(self) -> Selects:
        """Engine selectors of the events this subject may match."""
        own: set[tuple[str, str | None, str | None]] = set()
        if self.what in (None, "activity"):
            own.add((EventKind.ACTIVITY_COMPLETED, None, self.name))
        if self.what in (None, "trigger"):
            own.add((EventKind.TRIGGER_RAISED, None, None))
        if self.what in (None, "process"):
            own.add((EventKind.PROCESS_STARTED, self.name, None))
        for alt in self.alternatives:
            own |= alt.selects
        return frozenset(own)

    def spelling(self) -> str:
        """The text form that reads back as this subject: ``activity:a|b``."""
        own = f"{self.what}:{self.name}" if self.what else self.name
        return "|".join([own, *(alt.spelling() for alt in self.alternatives)])

    def bind(self, names: Names) -> Subject:
        """This subject with ``what`` resolved (activity, then trigger, then process);
        :class:`ConfigurationError` listing the spec's names when it has no such name."""
        alternatives = tuple(alt.bind(names) for alt in self.alternatives)
        table = {"activity": names.activities, "trigger": names.triggers,
                 "process": names.processes}
        if self.what is not None:
            if self.name not in table[self.what]:
                raise ConfigurationError(
                    f"the spec has no {self.what} {self.name!r}",
                    hint=f"its {self.what} names are: {', '.join(table[self.what]) or '(none)'}")
            return replace(self, alternatives=alternatives)
        for what, known in table.items():
            if self.name in known:
                return Subject(self.name, what, alternatives)
        raise ConfigurationError(
            f"the spec has no activity, trigger or process {self.name!r}",
            hint="its activities are: " + ", ".join(names.activities)
                 + "; triggers: " + (", ".join(names.triggers) or "(none)")
                 + "; processes: " + ", ".join(names.processes))


_KINDS = ("activity", "trigger", "process")
_NAME = re.compile(r"[\w.-]+")
_SPELT = re.compile(r"[\w.:-]+")       # a name after an explicit kind may hold a colon
_SUBJECT_HINT = ("write a name, optionally prefixed: activity:NAME, trigger:NAME, "
                 "process:NAME (or 'activity NAME'); 'a|b' for either")


def parse_subject(text: str) -> Subject:
    """``dispense``, ``activity:dispense``, ``activity dispense``, ``trigger:trg_2``,
    ``process:p``, ``a|b``."""
    words = split_words(text)
    subject, end = read_subject(words, 0)
    if end != len(words):
        raise ConfigurationError(f"cannot read {text.strip()!r} as an activity, trigger or "
                                 "process name", hint=_SUBJECT_HINT)
    return subject


def read_subject(tokens: Sequence[str], i: int) -> tuple[Subject, int]:
    """The subject that starts at ``tokens[i]`` (with its ``|`` alternatives) and the index
    after it; :class:`ConfigurationError` when the tokens there are not a name."""
    parts: list[Subject] = []
    while True:
        if i >= len(tokens):
            raise ConfigurationError("a name is missing", hint=_SUBJECT_HINT)
        token = tokens[i]
        what: str | None = None
        if token.lower() in _KINDS and i + 1 < len(tokens) and _SPELT.fullmatch(tokens[i + 1]):
            what, name, i = token.lower(), tokens[i + 1], i + 2
        else:
            head, colon, rest = token.partition(":")
            if colon and head.lower() in _KINDS:
                what, name = head.lower(), rest
            else:
                name = token
            i += 1
        pattern = _NAME if what is None else _SPELT
        if not pattern.fullmatch(name):
            raise ConfigurationError(f"cannot read {token!r} as an activity, trigger or "
                                     "process name", hint=_SUBJECT_HINT)
        parts.append(Subject(name, what))
        if i < len(tokens) and tokens[i] == "|":
            i += 1
            continue
        return replace(parts[0], alternatives=tuple(parts[1:])), i
