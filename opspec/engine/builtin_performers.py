"""Built-in performers: Python callables, scripted users (for tests and ``--script``), and
simulated devices.

All of them talk to the engine only through the
:class:`~opspec.engine.performers.PerformerSession` they are attached to.
"""

from __future__ import annotations

import functools
import json
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.errors import ConfigurationError, SourceLocation

__all__ = ["CallablePerformer", "ScriptedUser", "SimulatedDevice", "Step"]

Implementation = Callable[[Mapping[str, Any]], Mapping[str, Any] | None]


class _Base:
    session: PerformerSession | None = None

    def attach(self, session: PerformerSession) -> None:
        self.session = session

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """Nothing to undo by default."""

    def _session(self) -> PerformerSession:
        if self.session is None:
            raise RuntimeError(f"{type(self).__name__} was offered work before attach()")
        return self.session


class CallablePerformer(_Base):
    """Performs task activities with Python callables registered by Application id.

    A callable receives the activity's inputs (formal parameter id -> value; the instance's
    data when the application declares no parameters) and returns a mapping of outputs
    (formal parameter ids or data field names) or ``None``. If it raises, the activity fails
    with the exception's class name (``ValueError``...): the EXCEPTION transition naming it
    (or naming none) is taken, else the instance is aborted with a located message.
    """

    def __init__(self, applications: Mapping[str, Implementation] | None = None,
                 default: Implementation | None = None) -> None:
        self.applications: dict[str, Implementation] = dict(applications or {})
        self.default = default

    def register(self, application: str, implementation: Implementation) -> None:
        self.applications[application] = implementation

    def offer(self, item: WorkItem) -> None:
        session = self._session()
        function = self.applications.get(item.application or "", self.default)
        if function is None:
            session.fail(item, "NotImplemented",
                         f"no callable registered for application {item.application!r}")
            return
        try:
            result = function(item.data)
        except Exception as error:  # noqa: BLE001 - the user's code failed: an activity fault
            session.fail(item, type(error).__name__, str(error) or type(error).__name__)
            return
        session.complete(item, result)


class SimulatedDevice(_Base):
    """Completes device activities at once, or after their declared duration."""

    def offer(self, item: WorkItem) -> None:
        session = self._session()
        if item.duration:
            session.call_later(item.duration, lambda: session.complete(item))
        else:
            session.complete(item)


_VERBS = ("complete", "choose", "omit", "fail", "raise")


@dataclass(frozen=True, slots=True)
class Step:
    """One scripted action.

    ``verb`` is ``complete``/``choose``/``omit``/``fail`` (of an offered activity, ``target``)
    or ``raise`` (a trigger, ``target`` its name). ``delay`` is seconds after the matching
    offer, or, when ``absolute``, the simulated time (an offered activity then acts at
    ``max(offer, time)``). ``data`` is completed data; ``exception`` the name for ``fail``.
    ``repeat`` steps are never used up. ``instance`` (written ``#6`` in the action, as the
    walkthrough records it) limits the step to offers of that workflow instance.
    """

    verb: str
    target: str
    delay: float = 0.0
    absolute: bool = False
    data: Mapping[str, Any] | None = None
    exception: str = "failed"
    repeat: bool = False
    instance: int | None = None

    @classmethod
    def parse(cls, when: float | str, action: str, *, where: str = "<script>",
              repeat: bool = False) -> Step:
        """``(90.0, "complete walk_to_dispenser")``, ``("at 3600", "raise trg_1")``,
        ``(0, "choose press_report")``, ``(5, "fail take_pill dropped")``,
        ``(0, "complete weigh weight=71.5")``."""
        absolute = False
        if isinstance(when, str):
            text = when.strip()
            if text.startswith(("at ", "@")):
                absolute, text = True, text.removeprefix("at ").removeprefix("@")
            try:
                delay = float(text.removeprefix("+"))
            except ValueError:
                raise ConfigurationError(f"step time {when!r} is not a number of seconds",
                                         location=SourceLocation(where),
                                         hint="write 90, '+90' or 'at 3600'") from None
        else:
            delay = float(when)
        words = action.split()
        if len(words) < 2 or words[0] not in _VERBS:
            raise ConfigurationError(f"step action {action!r} is not understood",
                                     location=SourceLocation(where),
                                     hint="write VERB ACTIVITY with VERB one of "
                                          + ", ".join(_VERBS))
        verb, target, rest = words[0], words[1], words[2:]
        data: dict[str, Any] = {}
        exception = "failed"
        instance = None
        for word in rest:
            key, eq, value = word.partition("=")
            if word.startswith("#") and word[1:].isdigit():
                instance = int(word[1:])
            elif eq:
                data[key] = _value(value)
            elif verb == "fail":
                exception = word
        if delay < 0:
            raise ConfigurationError(f"step time {when!r} is negative",
                                     location=SourceLocation(where))
        return cls(verb, target, delay, absolute or verb == "raise", data or None, exception,
                   repeat, instance)


def _value(text: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


class ScriptedUser(_Base):
    """A user (or operator) following a fixed script: ``[(when, action), ...]``.

    On each offer the first unused step naming the offered activity (or one of its choices)
    is scheduled; ``default`` says what happens to an offer no step names: ``"wait"`` (it
    stays pending), ``"complete"`` (at once; a choice takes its first option) or
    ``"omit"``. ``log`` records ``(time, verb, activity)`` of everything done.
    """

    def __init__(self, steps: Sequence[Step | tuple[float | str, str]] = (), *,
                 default: str = "wait") -> None:
        if default not in ("wait", "complete", "omit"):
            raise ConfigurationError(f"default {default!r} is not known",
                                     location=SourceLocation("<script>", key="default"),
                                     hint="allowed values: wait, complete, omit")
        self.steps = [s if isinstance(s, Step) else Step.parse(*s) for s in steps]
        self.default = default
        self._used: set[int] = set()
        self.log: list[tuple[float, str, str]] = []
        self.offers: list[WorkItem] = []

    @classmethod
    def load(cls, path: str | Path) -> ScriptedUser:
        """Read a script: JSON or TOML with ``default`` and ``steps``, each step a table
        with ``do`` (the action) and ``after`` (seconds after the offer) or ``at``
        (absolute), optionally ``repeat``."""
        where = str(path)
        try:
            raw = Path(path).read_bytes()
            document = (tomllib.loads(raw.decode("utf-8")) if where.endswith(".toml")
                        else json.loads(raw))
        except FileNotFoundError:
            raise ConfigurationError("script file not found",
                                     location=SourceLocation(where)) from None
        except (ValueError, tomllib.TOMLDecodeError) as error:
            raise ConfigurationError(f"script is not valid JSON/TOML: {error}",
                                     location=SourceLocation(where)) from None
        if not isinstance(document, dict):
            raise ConfigurationError("a script is an object with 'steps'",
                                     location=SourceLocation(where))
        steps: list[Step] = []
        for n, entry in enumerate(document.get("steps", [])):
            key = f"steps[{n}]"
            if not isinstance(entry, dict) or "do" not in entry:
                raise ConfigurationError("each step needs 'do' (the action)",
                                         location=SourceLocation(where, key=key),
                                         hint='write {"after": 90, "do": "complete walk"}')
            unknown = set(entry) - {"do", "after", "at", "repeat"}
            if unknown:
                raise ConfigurationError(f"unknown step key(s) {', '.join(sorted(unknown))}",
                                         location=SourceLocation(where, key=key),
                                         hint="allowed keys: do, after, at, repeat")
            when: float | str = f"at {entry['at']}" if "at" in entry else entry.get("after", 0)
            steps.append(Step.parse(when, str(entry["do"]), where=f"{where}: {key}",
                                    repeat=bool(entry.get("repeat", False))))
        return cls(steps, default=str(document.get("default", "wait")))

    def attach(self, session: PerformerSession) -> None:
        self.session = session
        for index, step in enumerate(self.steps):
            if step.verb == "raise":
                self._used.add(index)
                session.call_later(max(0.0, step.delay - session.now),
                                   functools.partial(self._raise, step))

    def _raise(self, step: Step) -> None:
        session = self._session()
        self.log.append((session.now, "raise", step.target))
        session.raise_trigger(step.target, step.data)

    def offer(self, item: WorkItem) -> None:
        session = self._session()
        self.offers.append(item)
        for index, step in enumerate(self.steps):
            if index in self._used or step.verb == "raise":
                continue
            if step.instance is not None and step.instance != item.instance:
                continue
            if step.target == item.activity or step.target in item.choices:
                if not step.repeat:
                    self._used.add(index)
                delay = (max(0.0, step.delay - session.now) if step.absolute else step.delay)
                session.call_later(delay, functools.partial(self._act, step, item))
                return
        if self.default == "complete":
            self._act(Step("complete", item.choices[0] if item.choices else item.activity),
                      item)
        elif self.default == "omit":
            self._act(Step("omit", item.activity), item)

    def _act(self, step: Step, item: WorkItem) -> None:
        session = self._session()
        self.log.append((session.now, step.verb, step.target))
        choice = step.target if step.target in item.choices else None
        if step.verb in ("complete", "choose"):
            session.complete(item, step.data, choice=choice)
        elif step.verb == "omit":
            session.omit(item, "scripted")
        else:
            session.fail(item, step.exception, "scripted failure")
