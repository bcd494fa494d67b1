"""Message and signal names that nothing catches or nothing throws.

A misspelt message name is a valid file: the thrower raises ``report``, the catcher waits for
``reprot``, and every episode ends as a silent "cut off". This check pairs every name thrown
(a throwing event, ``opspec:Raises``) with every name awaited (a catching event, a start or
end trigger) within the packages loaded together, and warns about each name that has no
partner, naming the closest name of the other side (:func:`difflib.get_close_matches`).
Internal to :mod:`opspec.model.checks`.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.activities import Activity, Event, EventPosition, TriggerKind
from opspec.model.package import Package
from opspec.model.process import WorkflowProcess

__all__ = ["trigger_name_diagnostics"]

_KINDS = {TriggerKind.MESSAGE: "message", TriggerKind.SIGNAL: "signal"}
CODE_NOT_CAUGHT = "trigger-not-caught"
CODE_NOT_THROWN = "trigger-not-thrown"


@dataclass(frozen=True, slots=True)
class _Use:
    kind: str                     # "message" or "signal"
    name: str
    what: str                     # "activity 'a' of process 'p'"
    location: SourceLocation | None


def _event_uses(process: WorkflowProcess, activity: Activity
                ) -> tuple[list[_Use], list[_Use]]:
    thrown: list[_Use] = []
    caught: list[_Use] = []
    what = f"activity {activity.id!r} of process {process.id!r}"
    body = activity.body
    if isinstance(body, Event) and body.trigger.kind in _KINDS and body.trigger.name:
        use = _Use(_KINDS[body.trigger.kind], body.trigger.name, what, activity.location)
        throws = body.position is EventPosition.END or not body.trigger.catching
        (thrown if throws else caught).append(use)
    directives = activity.directives
    for trigger, side in ((directives.raises, thrown), (directives.start_trigger, caught),
                          (directives.end_trigger, caught)):
        if trigger is not None and trigger.kind in ("message", "signal") and trigger.name:
            side.append(_Use(trigger.kind, trigger.name, what,
                             trigger.location or activity.location))
    return thrown, caught


def _uses(packages: Iterable[Package]) -> tuple[list[_Use], list[_Use]]:
    thrown: list[_Use] = []
    caught: list[_Use] = []
    for package in packages:
        for process in package.processes:
            for trigger in (process.directives.start_trigger, process.directives.end_trigger):
                if trigger is not None and trigger.kind in ("message", "signal") and (
                        trigger.name):
                    caught.append(_Use(trigger.kind, trigger.name,
                                       f"process {process.id!r}",
                                       trigger.location or process.location))
            for activity in process.all_activities():
                more_thrown, more_caught = _event_uses(process, activity)
                thrown.extend(more_thrown)
                caught.extend(more_caught)
    return thrown, caught


def _closest(name: str, candidates: Iterable[str]) -> str | None:
    found = difflib.get_close_matches(name, sorted(set(candidates)), n=1, cutoff=0.6)
    return found[0] if found else None


def trigger_name_diagnostics(package: Package, packages: Mapping[str, Package]
                             ) -> list[Diagnostic]:
    """A warning for each message or signal of ``package`` that is thrown but never caught,
    or awaited but never thrown, by anything in the packages loaded with it."""
    everything = {package.id: package, **packages}
    thrown, caught = _uses(everything.values())
    own_thrown, own_caught = _uses((package,))
    fallback = SourceLocation(package.source or "<spec>")
    return [*_unmatched(own_thrown, caught, _NOT_CAUGHT, fallback),
            *_unmatched(own_caught, thrown, _NOT_THROWN, fallback)]


@dataclass(frozen=True, slots=True)
class _Side:
    """How one side's unmatched names are reported: the code, the verb and the hint."""

    code: str
    verb: str                 # "throws" / "waits for"
    missing: str              # "catches" / "throws"
    hint: str                 # "{fix}" stands for "fix the name (to 'x')"


_NOT_CAUGHT = _Side(CODE_NOT_CAUGHT, "throws", "catches",
                    "catch it (a catching event, a start trigger) or {fix}; a device or the "
                    "API may still catch it")
_NOT_THROWN = _Side(CODE_NOT_THROWN, "waits for", "throws",
                    "{fix} unless a device, a script, a user model or the API sends it")


def _unmatched(uses: list[_Use], partners: list[_Use], side: _Side,
               fallback: SourceLocation) -> list[Diagnostic]:
    """A warning for each name of ``uses`` (once per name) that no use of ``partners`` has,
    naming the closest name the partners do have."""
    have = {(u.kind, u.name) for u in partners}
    out: list[Diagnostic] = []
    seen: set[tuple[str, str]] = set()
    for use in uses:
        key = (use.kind, use.name)
        if key in have or key in seen:
            continue
        seen.add(key)
        close = _closest(use.name, (n for k, n in have if k == use.kind))
        fix = "fix the name" + (f" to {close!r}" if close else "")
        out.append(Diagnostic(
            use.location or fallback, Severity.WARNING, side.code,
            f"{use.what} {side.verb} {use.kind} {use.name!r}, which nothing in the spec "
            f"{side.missing}" + (f"; did you mean {close!r}?" if close else ""),
            side.hint.format(fix=fix)))
    return out
