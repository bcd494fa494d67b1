"""Who each recorded session is: sessions of one participant fitted as one person.

A trace file holds one or more runs (sessions). ``opspec fit`` estimates how much *people*
differ, and how uncertain its estimates are, from independent people — so two sessions of
one participant must count as one person, not two. :class:`PersonRule` says how a session
is mapped to a person, in the order a study coordinator would reach for:

1. ``--person FILE=ID`` (repeatable): that file's sessions are participant ``ID`` (``FILE``
   as given on the command line, its resolved path, or its bare file name);
2. ``--person-pattern REGEX``: the participant is the first group (else the whole match) of
   ``REGEX`` searched in the file's path nearest the file first (its name, then its folder,
   and up; a pattern that spans folders in the whole path), e.g. ``'(P\\d+)'`` for
   ``recordings/P07-day2.jsonl`` — a ``P1`` in a folder far above is not the participant;
3. ``--person-from``:

   * ``auto`` (default): the header's ``person`` key when the file has one, else each run
     is a person of its own (what fitting did before sessions were grouped);
   * ``header``: the header's ``person`` key, which every file must have;
   * ``file``: each file is one person (all its runs are sessions of that person);
   * ``folder``: the name of the folder holding the file (``recordings/P07/*.jsonl``);
   * ``run``: each run is a person of its own.

A session is ``(file index, run index)``; a person is a string.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from opspec.errors import SourceLocation, UserModelError
from opspec.usermodels.trace_reader import trace_header as _header

__all__ = ["PERSON_FROM", "PERSON_KEY", "PersonRule", "parse_person_options"]

PERSON_FROM = ("auto", "header", "file", "folder", "run")
#: the trace header key naming the participant (docs/trace-format.md)
PERSON_KEY = "person"


@dataclass(frozen=True)
class PersonRule:
    """How sessions map to persons (see the module docstring)."""

    source: str = "auto"
    pattern: str | None = None
    explicit: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.source not in PERSON_FROM:
            raise UserModelError(f"--person-from {self.source!r} is not known",
                                 hint="use one of: " + ", ".join(PERSON_FROM))
        if self.pattern is not None:
            try:
                re.compile(self.pattern)
            except re.error as error:
                raise UserModelError(f"--person-pattern {_typed(self.pattern)} is not a regular "
                                     f"expression: {error}",
                                     hint="for example '(P\\d+)' takes P07 out of "
                                     "recordings/P07-day2.jsonl") from None

    def of_file(self, path: Path) -> str | None:
        """The person every session of ``path`` belongs to; None: each run its own person."""
        found = self._explicit(path)
        if found is not None:
            return found
        if self.pattern is not None:
            match = _nearest_match(self.pattern, path)
            if match is None:
                raise UserModelError(
                    f"--person-pattern {_typed(self.pattern)} does not match this file's path",
                    location=SourceLocation(str(path)),
                    hint="fix the pattern, or name the file's person with --person "
                    f"{path.name}=ID")
            return match.group(1) if match.groups() and match.group(1) else match.group(0)
        if self.source == "run":
            return None
        if self.source == "file":
            return str(path)
        if self.source == "folder":
            return path.resolve().parent.name
        person = _header(path).get(PERSON_KEY)
        if person is not None and str(person).strip():
            return str(person)
        if self.source == "header":
            raise UserModelError(
                f"the trace header has no {PERSON_KEY!r} key: whose session is it?",
                location=SourceLocation(str(path), 1),
                hint=f"name the person with --person {path.name}=ID, or group by "
                "--person-from file|folder|run")
        return None

    def _explicit(self, path: Path) -> str | None:
        for key in (str(path), path.name):
            if key in self.explicit:
                return self.explicit[key]
        try:
            resolved = path.resolve()
        except OSError:
            return None
        for key, person in self.explicit.items():
            try:
                if Path(key).resolve() == resolved:
                    return person
            except OSError:
                continue
        return None

    def check_used(self, paths: Sequence[Path]) -> None:
        """Every ``--person FILE=ID`` names one of the traces (a typo is not silently
        ignored)."""
        names = {str(p) for p in paths} | {p.name for p in paths}
        resolved = set()
        for p in paths:
            try:
                resolved.add(p.resolve())
            except OSError:
                pass
        for key in self.explicit:
            try:
                hit = key in names or Path(key).resolve() in resolved
            except OSError:
                hit = key in names
            if not hit:
                raise UserModelError(f"--person {key}={self.explicit[key]}: {key} is not one "
                                     "of the traces given",
                                     hint="name a trace file as given on the command line, "
                                     "or its file name")


def parse_person_options(values: Sequence[str]) -> dict[str, str]:
    """``["a.jsonl=P1", "b.jsonl=P1"]`` -> ``{"a.jsonl": "P1", "b.jsonl": "P1"}``."""
    out: dict[str, str] = {}
    for value in values:
        file, sep, person = value.rpartition("=")
        if not sep or not file or not person.strip():
            raise UserModelError(f"--person {value!r} is not FILE=ID",
                                 hint="for example --person recordings/s1.jsonl=P07")
        if file in out and out[file] != person:
            raise UserModelError(f"--person names {file} twice ({out[file]} and {person})")
        out[file] = person.strip()
    return out


def _nearest_match(pattern: str, path: Path) -> re.Match[str] | None:
    """``pattern`` searched in ``path``'s parts from the file's name upwards, then (a pattern
    that spans folders) in the whole path: the participant is named nearest the file, and a
    folder far above it (a study's, a temporary one) must not name every file alike."""
    for part in reversed(path.parts):
        match = re.search(pattern, part)
        if match is not None:
            return match
    return re.search(pattern, str(path))


def _typed(pattern: str) -> str:
    """The pattern as it is typed in a shell: ``'(P\\d+)'``, not Python's repr with its
    doubled backslash, which pasted back is another pattern."""
    import shlex

    return shlex.quote(pattern)
