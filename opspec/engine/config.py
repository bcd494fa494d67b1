"""Engine configuration: processor model, workers, priorities, timer resolution, switch cost.

The configuration of the source design's *engine manager* (maximum number of workflow
processing threads, timer resolution, number of priorities) plus what opspec needs to simulate
both processor models and the wall-clock mode. It is an immutable value; build it with keyword
arguments or load it from TOML::

    [engine]
    processor_model = "pooled"     # "dedicated" | "pooled" | "preemptive" | "priority-queues"
    workers = 2                    # pooled: workers; preemptive, priority-queues: processors
    queue_workers = 1              # priority-queues: worker threads per priority queue
    priorities = 4
    timer_resolution = 0.01        # seconds; 0 = exact
    switch_cost = 0.0005           # seconds per transition between general activities (pooled)
    realtime = false
    speed = 1.0                    # wall-clock mode: simulated seconds per wall second

Keys may also sit at the top level of the file (then without an ``[engine]`` table: beside
one, a key outside it is refused, not ignored). Unknown keys and bad values raise
:class:`~opspec.errors.ConfigurationError` naming ``path:line: key`` and what is allowed.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal

from opspec.errors import ConfigurationError, SourceLocation
from opspec.toml_lines import located

__all__ = ["PROCESSOR_MODELS", "EngineConfig"]

PROCESSOR_MODELS = ("dedicated", "pooled", "preemptive", "priority-queues")


@dataclass(frozen=True, slots=True, kw_only=True)
class EngineConfig:
    """How the engine executes a package.

    - ``processor_model``: ``"dedicated"`` (each workflow instance has its own worker,
      transitions are free, priority increments are ignored) or ``"pooled"`` (``workers``
      workers serve one FIFO queue per priority level; every transition into a general
      activity costs ``switch_cost`` seconds of a worker; ``cpu_demand`` occupies a worker).
    - ``"preemptive"``: ``workers`` processors scheduled by fixed priority with preemption
      (the source's Linux engine: a thread per workflow at its priority): a ready activity of
      a higher level takes a processor from the lowest-level one running, which resumes
      later (charged ``switch_cost`` again); equal levels are served in arrival order.
    - ``"priority-queues"``: the source's Windows CE engine: a FIFO queue per priority level
      with ``queue_workers`` worker threads of its own, a leader thread above them that
      queues work and handles completions, on ``workers`` processors with fixed-priority
      preemption; every start or resumption of a thread on a processor costs
      ``switch_cost`` (docs/processor-models.md).
    - ``workers``: workers of the pooled model, processors of the preemptive and
      priority-queues models (>= 1); ``queue_workers``: worker threads per queue (>= 1).
    - ``priorities``: number of priority levels (>= 1); effective priorities are clamped to
      ``0 .. priorities-1`` and the highest level is served first.
    - ``timer_resolution``: timers (start triggers, timer events, deadlines) fire on the next
      multiple of this many seconds; ``0`` means exactly.
    - ``switch_cost``: seconds a pooled worker spends per transition to a general activity.
    - ``realtime`` / ``speed``: run against the wall clock, ``speed`` simulated seconds per
      wall-clock second.
    - ``message_ttl``: seconds a message nobody waits for is kept for the next activity that
      waits for it (docs/semantics.md); older ones are lost (``trigger.lost``). ``None`` (the
      default): what the spec's ``opspec:MessageTTL`` says, and without it messages are kept
      until caught or their receiver ends (BPMN: a message waits for its catcher); ``inf``
      keeps them so whatever the spec says.
    """

    processor_model: Literal["dedicated", "pooled", "preemptive", "priority-queues"] = "dedicated"
    workers: int = 1
    queue_workers: int = 1
    priorities: int = 8
    timer_resolution: float = 0.0
    switch_cost: float = 0.0
    realtime: bool = False
    speed: float = 1.0
    message_ttl: float | None = None

    def __post_init__(self) -> None:
        _check(self, None)

    @property
    def pooled(self) -> bool:
        """Whether a shared set of processors schedules the general activities (the pooled
        and the preemptive model; the dedicated model gives every instance its own)."""
        return self.processor_model != "dedicated"

    @classmethod
    def from_mapping(
        cls, values: Mapping[str, Any], *, path: str = "<options>", base: EngineConfig | None = None
    ) -> EngineConfig:
        """A configuration from ``values`` (unknown keys rejected), on top of ``base``."""
        allowed = {f.name for f in fields(cls)}
        for key in values:
            if key not in allowed:
                raise ConfigurationError(
                    f"unknown engine option {key!r}",
                    location=SourceLocation(_shown(path), key=key),
                    hint=f"allowed options: {', '.join(sorted(allowed))}",
                )
        merged = {f.name: getattr(base or _DEFAULT, f.name) for f in fields(cls)}
        merged.update(values)
        for key in ("workers", "priorities", "queue_workers"):
            if isinstance(merged[key], float) and merged[key].is_integer():
                merged[key] = int(merged[key])
        config = object.__new__(cls)
        for key, value in merged.items():
            object.__setattr__(config, key, value)
        _check(config, path)
        return config

    @classmethod
    def load(cls, path: str | Path, **overrides: Any) -> EngineConfig:
        """Read a TOML file (``[engine]`` table or top-level keys), then apply ``overrides``."""
        from opspec.toml_files import read_toml

        text_path = str(path)
        # bounded (size, nesting) and located like every TOML file people write
        document = read_toml(path, what="the engine configuration")
        table = document.get("engine", document)
        if not isinstance(table, dict):
            raise ConfigurationError("[engine] must be a table",
                                     location=located(text_path, "engine"))
        if table is not document:
            # beside an [engine] table, a key at the top (or one written after another
            # table) would be left out without a word
            for key in document:
                if key != "engine":
                    raise ConfigurationError(
                        f"{key!r} is outside the [engine] table, so it would be ignored",
                        location=located(text_path, key),
                        hint="move it under [engine] (keys after a [table] line belong to "
                        "that table), or write every key at the top and leave out [engine]")
        prefix = "engine." if table is not document else ""
        table = {k: v for k, v in table.items() if k != "engine"}
        try:
            config = cls.from_mapping(table, path=text_path)
        except ConfigurationError as error:
            raise _at_its_line(error, text_path, prefix) from None
        return config.with_options(**overrides) if overrides else config

    def with_options(self, **overrides: Any) -> EngineConfig:
        """A copy with keyword ``overrides`` applied (validated like the file). The command
        line's options arrive here (opspec run's ``--speed``, ``--workers``…), so a bad value
        is named as the option that sets it: ``--speed must be a number > 0, not 0``."""
        return EngineConfig.from_mapping(overrides, path=COMMAND_LINE, base=self)


#: the ``path`` of values given as keyword options (:meth:`EngineConfig.with_options`): the
#: command line's, whose errors name the option, not a file and key
COMMAND_LINE = "<command line>"

#: the command-line option that sets each key (a file sets the others)
_OPTIONS = {"workers": "--workers", "queue_workers": "--queue-workers",
            "switch_cost": "--switch-cost", "speed": "--speed"}


def _shown(path: str | None) -> str:
    """Where keyword options are said to come from when no command-line option names them."""
    return "<options>" if path is None or path == COMMAND_LINE else path


def _at_its_line(error: ConfigurationError, path: str, table: str) -> ConfigurationError:
    """``error`` about a key of the file ``path`` placed at the line it is written on
    (``table``: the table the keys are in, ``"engine."``), the key shown as before."""
    at = error.location
    if at is None or at.path != path or not at.key or at.line is not None:
        return error
    line = located(path, f"{table}{at.key}").line
    return ConfigurationError(error.message, location=SourceLocation(path, line, at.key),
                              hint=error.hint)


def _fail(path: str | None, key: str, message: str, hint: str) -> ConfigurationError:
    return ConfigurationError(message, location=SourceLocation(_shown(path), key=key), hint=hint)


def _bad_value(path: str | None, key: str, requirement: str, value: Any, example: str,
               why: str = "") -> ConfigurationError:
    """``key must be REQUIREMENT, not VALUE`` at ``path: key`` (a file's line added by
    :meth:`EngineConfig.load`) with the TOML to write, or, for
    a command-line option, as the option: ``--speed must be a number > 0, not 0``."""
    option = _OPTIONS.get(key)
    if path == COMMAND_LINE and option is not None:
        shown = f"{value:g}" if isinstance(value, float) else repr(value)
        return ConfigurationError(f"{option} must be {requirement}, not {shown}",
                                  hint=f"e.g. {option} {example}{why}")
    return _fail(path, key, f"{key} must be {requirement}, not {value!r}",
                 f"write e.g. {key} = {example}{why}")


def _check(config: EngineConfig, path: str | None) -> None:
    if config.processor_model not in PROCESSOR_MODELS:
        raise _fail(path, "processor_model",
                    f"processor_model {config.processor_model!r} is not known",
                    f"allowed values: {', '.join(PROCESSOR_MODELS)}")
    for key in ("workers", "priorities", "queue_workers"):
        value = getattr(config, key)
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise _bad_value(path, key, "a whole number >= 1", value, "2")
    for key in ("timer_resolution", "switch_cost", "message_ttl"):
        value = getattr(config, key)
        if value is None and key == "message_ttl":
            continue
        if (isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value)
                or (not math.isfinite(value) and key != "message_ttl") or value < 0):
            raise _bad_value(path, key, "a number of seconds >= 0", value, "0.001")
    if not isinstance(config.realtime, bool):
        raise _fail(path, "realtime", f"realtime must be true or false, not {config.realtime!r}",
                    "allowed values: true, false")
    speed = config.speed
    if (isinstance(speed, bool) or not isinstance(speed, int | float)
            or not math.isfinite(speed) or speed <= 0):
        raise _bad_value(path, "speed", "a number > 0", speed, "60",
                         " (one simulated minute per wall second)")


_DEFAULT = EngineConfig()
