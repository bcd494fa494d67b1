"""The numbers an evaluation can sweep (``opspec evaluate --sweep``): the spec's and the user
model's, each by one name, with its unit.

Names (``docs/evaluation.md``, *Sweeps*):

* ``spec.FIELD`` / ``spec.PROCESS.FIELD`` — the initial value of a package's / a workflow's
  data field of type INTEGER, FLOAT or BOOLEAN (a number the device is configured with: the
  number of alarms, a volume). A number written inside an expression (``alarms < 3``) is not a
  parameter: name it as a data field and the sweep can reach it;
* ``spec.PROCESS.ACTIVITY.deadline`` — an activity's Deadline with a fixed duration (the
  re-alert interval: the deadline of the dispenser's ``wait_report``); an activity with
  several deadlines names each by its exception, ``deadline.EXCEPTION``;
* ``spec.PROCESS.ACTIVITY.timer`` — a timer event's fixed duration;
* ``spec.PROCESS.period`` — a workflow's ``opspec:Period``;
* ``user.PATH`` — a number of the user model, by the same paths a population's ``[vary]``
  uses (:mod:`opspec.usermodels.population`): ``user.activities.hear_alarm.omission.probability``
  (``…omission`` alone means its probability), ``user.activities.walk_to_dispenser.duration.median``,
  ``user.routine.windows.asleep.start``, and ``user.modifier.duration_factor`` /
  ``notice_factor`` / ``tail_fraction`` (a modifier applied to the whole model: general
  slowing, a lower chance of noticing every prompt).

A value is read in its parameter's unit: durations in :mod:`opspec.clock`'s grammar (``5 min``,
``PT5M``, ``300``), probabilities as ``0.05`` or ``5%``, times of day as ``08:00``, rates as
``0.1/s``. Designs carry ``(name, value)`` pairs; :func:`apply_parameters` makes the spec and
the user model each design runs with (in the worker: every value is resolved again there).
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from opspec.errors import EvaluationError, OpspecError

__all__ = ["UNITS", "Parameter", "apply_parameters", "parse_value", "resolve",
           "sweepable"]

#: What a value of each unit looks like (said when one does not parse).
UNITS: Mapping[str, str] = {
    "duration": "a duration: 300 (seconds), 5 min, 1h30m, PT5M or 00:05:00",
    "probability": "a probability: 0.05 or 5%",
    "number": "a number, e.g. 1.5",
    "factor": "a number >= 0, e.g. 1.2",
    "integer": "a whole number, e.g. 3",
    "boolean": "true or false",
    "time of day": "a time of day, e.g. 08:00 or 23:30",
    "rate": "a rate: 0.1 (per second), 6/min, 2/h",
}

# per duration kind: the parameters a person can differ in (opspec.usermodels.population) and
# the unit each is read in
_DURATION_UNITS: Mapping[str, Mapping[str, str]] = {
    "constant": {"value": "duration"},
    "lognormal": {"median": "duration", "mean": "duration", "sigma": "number",
                  "mu": "number"},
    "gamma": {"shape": "number", "scale": "duration", "mean": "duration", "rate": "rate"},
    "weibull": {"shape": "number", "scale": "duration"},
    "normal": {"mean": "duration", "sd": "duration", "low": "duration", "high": "duration"},
    "exponential": {"mean": "duration", "rate": "rate"},
    "exgauss": {"mu": "duration", "sigma": "duration", "tau": "duration"},
    "triangular": {"low": "duration", "mode": "duration", "high": "duration"},
    "uniform": {"low": "duration", "high": "duration"},
    "empirical": {"jitter": "duration"},
}
_PROBABILITY_PARTS = ("omission", "commission", "repetition", "delay")
_WINDOW_UNITS = {"start": "time of day", "end": "time of day", "notice_factor": "factor",
                 "duration_factor": "factor", "probability": "probability"}
_DRIFT_FIELDS = ("notice_factor_per_day", "min_notice_factor", "duration_factor_per_day",
                 "min_duration_factor")
_MODIFIER_UNITS = {"duration_factor": "factor", "notice_factor": "probability",
                   "tail_fraction": "factor"}


@dataclass(frozen=True, slots=True)
class Parameter:
    """One sweepable number: its ``name``, the ``unit`` its values are read in (a key of
    :data:`UNITS`), its ``current`` value in the spec or model, and ``what`` it is, in words.
    ``target`` says where it lives (for :func:`apply_parameters`)."""

    name: str
    unit: str
    current: Any
    what: str
    target: tuple[Any, ...] = ()

    @property
    def side(self) -> str:
        """``spec`` or ``user``."""
        return self.name.split(".", 1)[0]


# ------------------------------------------------------------------------------ the spec


def _literal_seconds(expression: Any, text: str | None) -> float | None:
    """The fixed number of seconds of a deadline or timer, None when it is computed."""
    from opspec.clock import try_duration
    from opspec.model.expressions import Literal

    if isinstance(expression, Literal) and isinstance(expression.value, (int, float)) \
            and not isinstance(expression.value, bool):
        return float(expression.value)
    if expression is None and text:
        return try_duration(text)
    return None


def _field_parameters(prefix: str, fields: Iterable[Any], where: tuple[Any, ...]
                      ) -> list[Parameter]:
    from opspec.model.data import BasicKind, BasicType

    units = {BasicKind.INTEGER: "integer", BasicKind.FLOAT: "number",
             BasicKind.BOOLEAN: "boolean"}
    out = []
    for field in fields:
        if isinstance(field.type, BasicType) and field.type.kind in units and \
                not field.is_array:
            out.append(Parameter(f"{prefix}{field.id}", units[field.type.kind], field.initial,
                                 f"initial value of data field {field.id!r}"
                                 + (f" of {where[1]}" if where[1] else ""),
                                 ("field", *where, field.id)))
    return out


def _activities(process: Any) -> list[Any]:
    return [*process.activities, *(a for s in process.activity_sets for a in s.activities)]


def spec_parameters(package: Any) -> dict[str, Parameter]:
    """Every sweepable number of ``package`` (an :class:`opspec.model.Package`), by name."""
    from opspec.model.activities import Event, TriggerKind

    found = _field_parameters("spec.", package.data_fields, ("package", None))
    for process in package.processes:
        base = f"spec.{process.id}."
        found += _field_parameters(base, process.data_fields, ("process", process.id))
        if process.directives.period is not None:
            found.append(Parameter(f"{base}period", "duration", process.directives.period,
                                   f"period of workflow {process.id!r} (opspec:Period)",
                                   ("period", process.id)))
        for activity in _activities(process):
            fixed = [(i, d) for i, d in enumerate(activity.deadlines)
                     if _literal_seconds(d.duration, d.duration_text) is not None]
            for i, deadline in fixed:
                suffix = "deadline" if len(activity.deadlines) == 1 else \
                    f"deadline.{deadline.exception_name or i + 1}"
                found.append(Parameter(
                    f"{base}{activity.id}.{suffix}", "duration",
                    _literal_seconds(deadline.duration, deadline.duration_text),
                    f"deadline of activity {activity.id!r} in {process.id!r}",
                    ("deadline", process.id, activity.id, i)))
            body = activity.body
            if isinstance(body, Event) and body.trigger.kind is TriggerKind.TIMER and \
                    body.trigger.date is None and body.trigger.repeat == 0:
                seconds = _literal_seconds(body.trigger.duration, body.trigger.time_cycle)
                if seconds is not None:
                    found.append(Parameter(f"{base}{activity.id}.timer", "duration", seconds,
                                           f"timer of event {activity.id!r} in "
                                           f"{process.id!r}", ("timer", process.id,
                                                               activity.id)))
    # a name taken twice (a data field called "period") keeps the first: the data field
    return _first(found)


def _first(found: Sequence[Parameter]) -> dict[str, Parameter]:
    out: dict[str, Parameter] = {}
    for parameter in found:
        out.setdefault(parameter.name, parameter)
    return out


def _with_activity(process: Any, activity_id: str, change: Any) -> Any:
    activities = tuple(change(a) if a.id == activity_id else a for a in process.activities)
    sets = tuple(replace(s, activities=tuple(change(a) if a.id == activity_id else a
                                             for a in s.activities))
                 for s in process.activity_sets)
    return replace(process, activities=activities, activity_sets=sets)


def _set_spec(package: Any, parameter: Parameter, value: Any) -> Any:
    from opspec.model.expressions import Literal

    kind, *where = parameter.target
    if kind == "field":
        scope, process_id, field_id = where
        text = ("true" if value else "false") if isinstance(value, bool) else repr(value)

        def field(f: Any) -> Any:
            return replace(f, initial=value, initial_value=text) if f.id == field_id else f

        if scope == "package":
            return replace(package, data_fields=tuple(map(field, package.data_fields)))
        return replace(package, processes=tuple(
            replace(p, data_fields=tuple(map(field, p.data_fields))) if p.id == process_id
            else p for p in package.processes))
    process_id = where[0]
    if kind == "period":
        def change_process(p: Any) -> Any:
            return replace(p, directives=replace(p.directives, period=float(value)))
    elif kind == "deadline":
        activity_id, index = where[1], where[2]

        def change_activity(a: Any) -> Any:
            deadlines = list(a.deadlines)
            deadlines[index] = replace(deadlines[index], duration=Literal(float(value)),
                                       duration_text=f"PT{float(value):g}S")
            return replace(a, deadlines=tuple(deadlines))

        def change_process(p: Any) -> Any:
            return _with_activity(p, activity_id, change_activity)
    else:                                       # a timer event
        activity_id = where[1]

        def change_timer(a: Any) -> Any:
            trigger = replace(a.body.trigger, duration=Literal(float(value)))
            return replace(a, body=replace(a.body, trigger=trigger))

        def change_process(p: Any) -> Any:
            return _with_activity(p, activity_id, change_timer)
    return replace(package, processes=tuple(change_process(p) if p.id == process_id else p
                                            for p in package.processes))


# ------------------------------------------------------------------------ the user model


def _duration_parameters(prefix: str, dist: Any, what: str) -> list[Parameter]:
    from opspec.usermodels.distributions import WithExponentialTail

    out = []
    tail = None
    if isinstance(dist, WithExponentialTail):
        dist, tail = dist.base, dist.tau
    params = dist.to_params()
    kind = str(params.get("kind"))
    for name, unit in _DURATION_UNITS.get(kind, {}).items():
        current = params.get(name)
        if current is None and kind == "lognormal" and name == "median" and "mu" in params:
            current = math.exp(float(params["mu"]))
        elif current is None and kind == "lognormal" and name == "mu" and "median" in params:
            current = math.log(float(params["median"]))
        elif current is None and name == "mean":
            current = dist.mean
        elif current is None and name == "rate" and dist.mean:
            current = 1.0 / dist.mean
        out.append(Parameter(f"{prefix}.{name}", unit, current, f"{what}: {kind} {name}"))
    if tail is not None:
        out.append(Parameter(f"{prefix}.tau", "duration", tail, f"{what}: slow tail's mean"))
    return out


def _activity_parameters(prefix: str, activity: Any, what: str) -> list[Parameter]:
    out = _duration_parameters(f"{prefix}.duration", activity.duration, f"{what} duration")
    for part in _PROBABILITY_PARTS:
        current = getattr(activity, part)
        if current is None:
            continue
        out.append(Parameter(f"{prefix}.{part}.probability", "probability",
                             current.probability, f"{what} {part} probability"))
        if part == "commission" and current.recovery is not None:
            out += _duration_parameters(f"{prefix}.commission.recovery", current.recovery,
                                        f"{what} recovery after a slip")
        if part == "delay":
            out += _duration_parameters(f"{prefix}.delay.duration", current.duration,
                                        f"{what} extra delay")
    return out


def user_parameters(model: Any) -> dict[str, Parameter]:
    """Every sweepable number of ``model`` (an :class:`opspec.usermodels.UserModel`)."""
    found: list[Parameter] = []
    for activity_id, activity in model.activities.items():
        found += _activity_parameters(f"user.activities.{activity_id}", activity,
                                      f"activity {activity_id!r}:")
    if model.default is not None:
        found += _activity_parameters("user.defaults", model.default, "[defaults]:")
    for window in model.routine.windows:
        for name, unit in _WINDOW_UNITS.items():
            found.append(Parameter(f"user.routine.windows.{window.name}.{name}", unit,
                                   getattr(window, name, None),
                                   f"routine window {window.name!r}: {name}"))
    for name in _DRIFT_FIELDS:
        found.append(Parameter(f"user.routine.drift.{name}", "factor",
                               getattr(model.routine.drift, name, None),
                               f"adherence drift: {name}"))
    for name, unit in _MODIFIER_UNITS.items():
        found.append(Parameter(f"user.modifier.{name}", unit,
                               0.0 if name == "tail_fraction" else 1.0,
                               f"a modifier of the whole model: {name}"))
    return _first(found)


def _set_user(model: Any, parameter: Parameter, value: Any) -> Any:
    from opspec.usermodels.model import Modifier
    from opspec.usermodels.population import set_parameter

    path = tuple(parameter.name.split(".")[1:])
    if path[0] == "modifier":
        factors: dict[str, Any] = {path[1]: float(value)}
        return model.with_modifier(Modifier(name=f"{parameter.name} = {value:g}", **factors))
    changed = set_parameter(model, path, float(value))
    if model.population is None:
        return changed
    return replace(changed, population=model.population.map_models(
        lambda m: set_parameter(m, path, float(value))))


# ------------------------------------------------------------------------------- naming


def sweepable(package: Any, model: Any) -> dict[str, Parameter]:
    """Every sweepable parameter of the spec and (when there is one) the user model."""
    found = spec_parameters(package)
    if model is not None:
        found.update(user_parameters(model))
    return found


_SHORTHAND = re.compile(r"(user\.(?:activities\.[^.]+|defaults)\.(?:omission|commission|"
                        r"repetition|delay))$")


def resolve(name: str, package: Any, model: Any, *, where: str = "") -> Parameter:
    """The parameter ``name`` names; an EvaluationError with the closest names and every
    sweepable one when it names none (or names one a population draws per user)."""
    known = sweepable(package, model)
    wanted = name.strip()
    if _SHORTHAND.match(wanted):
        wanted += ".probability"
    found = known.get(wanted)
    if found is None:
        guesses = [f"{side}.{wanted}" for side in ("spec", "user")
                   if f"{side}.{wanted}" in known]
        guesses += [g for g in difflib.get_close_matches(wanted, list(known), n=3,
                                                         cutoff=0.8) if g not in guesses]
        raise EvaluationError(
            f"--sweep {name}: {where or 'the spec and the user model'} "
            f"{'have' if model is not None else 'has'} no parameter of that name"
            + (f"; did you mean {' or '.join(guesses)}?" if guesses else ""),
            hint="sweepable: " + (", ".join(known) or "none") + " (`opspec evaluate SPEC "
            "--sweep list` lists them with their current values; docs/evaluation.md, Sweeps)")
    if model is not None and model.population is not None and found.side == "user":
        path = found.name.split(".", 1)[1]
        varied = model.population.parameters
        # a modifier is composed on top of each person (their own drawn factor times it):
        # sweeping one keeps how people differ; setting a drawn number would erase it
        if path in varied and not path.startswith("modifier."):
            raise EvaluationError(
                f"--sweep {found.name}: the population draws this parameter per user "
                "(its [vary] table), so one value for everybody would erase how people "
                "differ", hint="sweep a modifier, which is applied on top of each person "
                "(user.modifier.duration_factor, user.modifier.notice_factor), or a "
                "parameter the population does not vary (it varies: "
                + ", ".join(varied) + "), or write one population file per value")
    return found


def parse_value(parameter: Parameter, text: str) -> Any:
    """``text`` read in the unit of ``parameter``; an EvaluationError naming the parameter,
    the value and the unit expected when it does not parse or is out of range."""
    from opspec.clock import parse_duration, parse_rate, parse_time_of_day

    raw = text.strip()

    def refuse(problem: str = "") -> EvaluationError:
        return EvaluationError(
            f"--sweep {parameter.name}: cannot read {raw!r}"
            + (f": {problem}" if problem else "") + f" (expected {UNITS[parameter.unit]})",
            hint=f"{parameter.name} is {parameter.what}"
            + (f", now {describe_value(parameter, parameter.current)}"
               if parameter.current is not None else ""))

    unit = parameter.unit
    try:
        if unit == "duration":
            return parse_duration(raw, error=EvaluationError)
        if unit == "time of day":
            return parse_time_of_day(raw, error=EvaluationError)
        if unit == "rate":
            return parse_rate(raw, error=EvaluationError)
    except OpspecError as error:
        raise refuse(error.message.split(": ", 1)[-1]) from None
    if unit == "boolean":
        lowered = raw.lower()
        if lowered in ("true", "yes", "1", "on"):
            return True
        if lowered in ("false", "no", "0", "off"):
            return False
        raise refuse()
    if unit == "integer":
        if not re.fullmatch(r"[+-]?\d+", raw):
            raise refuse()
        return int(raw)
    percent = raw.endswith("%")
    try:
        value = float(raw[:-1] if percent else raw) / (100.0 if percent else 1.0)
    except ValueError:
        raise refuse() from None
    if not math.isfinite(value):
        raise refuse("not a finite number")
    if percent and unit not in ("probability",):
        raise refuse("a percentage is a probability, and this is not one")
    if unit == "probability" and not 0.0 <= value <= 1.0:
        raise refuse("a probability lies between 0 and 1 (write 5% or 0.05)")
    if unit == "factor" and value < 0:
        raise refuse("it cannot be negative")
    return value


def describe_value(parameter: Parameter, value: Any) -> str:
    """``value`` as a reader writes it in the parameter's unit: ``5 min``, ``2 %``, ``08:00``."""
    from opspec.clock import span, time_of_day

    if value is None:
        return "–"
    if isinstance(value, bool):
        return "true" if value else "false"
    if parameter.unit == "duration":
        return span(float(value))
    if parameter.unit == "time of day":
        return time_of_day(float(value))
    if parameter.unit == "probability":
        return f"{100.0 * float(value):.4g} %"
    if parameter.unit == "rate":
        return f"{float(value):.4g}/s"
    return f"{value:g}" if isinstance(value, float) else str(value)


def apply_parameters(loaded: Any, model: Any, parameters: Sequence[Sequence[Any]]
                     ) -> tuple[Any, Any]:
    """The spec (a Package when changed, else ``loaded`` itself) and the user model
    ``(name, value)`` ``parameters`` make of ``loaded`` (an :class:`opspec.runs.LoadedSpec`)
    and ``model``. A value the spec or the model does not allow is an EvaluationError naming
    the parameter."""
    package = loaded.package
    changed = False
    for name, value in parameters:
        parameter = resolve(str(name), package, model)
        try:
            if parameter.side == "spec":
                package, changed = _set_spec(package, parameter, value), True
            else:
                model = _set_user(model, parameter, value)
        except (OpspecError, ValueError, TypeError) as error:    # a ParameterError too
            detail = getattr(error, "detail", None) or getattr(error, "message", None) \
                or str(error)
            raise EvaluationError(f"--sweep {parameter.name}={value!r}: {detail}",
                                  hint=f"{parameter.name} is {parameter.what}") from None
    return (package if changed else loaded), model
