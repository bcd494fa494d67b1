"""Words for a report's reader: what each metric measures, who the simulated users are.

- :func:`metric_record` turns a spec's :class:`~opspec.model.sisarl.MetricDefinition` into the
  JSON the result store keeps (``run.metrics``), selectors included, so a report written from
  the store alone can say from which event to which event a duration runs;
- :func:`describe_metric` says it in words (the spec's own ``Description`` first, then how it
  is computed from the trace);
- :func:`user_model_rows` and :func:`user_model_notes` list a user model's parameters and
  assumptions (durations, omissions, errors, routines, modifiers, with their sources);
  :func:`can_do_wrongly` says whether it has a wrong action for an activity at all.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from opspec.clock import time_of_day

if TYPE_CHECKING:
    from opspec.model.sisarl import EventSelector, MetricDefinition
    from opspec.usermodels.distbase import Distribution
    from opspec.usermodels.model import ActivityModel, UserModel
    from opspec.usermodels.population import Population

__all__ = ["can_do_wrongly", "correlation_rows", "describe_metric", "describe_selector",
           "metric_record", "population_notes", "user_model_notes", "user_model_rows",
           "variation_rows"]


def _selector(selector: EventSelector | None) -> dict[str, Any] | None:
    if selector is None:
        return None
    return {"event": selector.event, "process": selector.process,
            "activity": selector.activity, "which": selector.which}


def metric_record(metric: MetricDefinition) -> dict[str, Any]:
    """The stored form of one declared metric (``run.metrics`` in ``results.sqlite``);
    ``proportion`` is the spec's declaration (``Proportion="true"``), which the summaries
    read to choose a ratio's interval (a store written before it was kept has none: every
    ratio of it is a ratio)."""
    return {"name": metric.name, "kind": metric.kind.value.lower(),
            "numerator": metric.numerator, "denominator": metric.denominator,
            "proportion": metric.proportion,
            "unit": metric.unit, "description": metric.description,
            "select": _selector(metric.select), "start": _selector(metric.start),
            "end": _selector(metric.end)}


_EVENTS = {
    "process.started": "start of",
    "process.completed": "completion of",
    "process.terminated": "termination of",
    "process.aborted": "abortion of",
    "activity.started": "start of",
    "activity.offered": "offer of",
    "activity.completed": "completion of",
    "activity.withdrawn": "withdrawal of",
    "activity.omitted": "omission of",
    "activity.failed": "failure of",
    "activity.aborted": "abortion of",
    "trigger.raised": "raising of a trigger in",
    "deadline.expired": "expiry of a deadline in",
    "exception.raised": "exception raised in",
}


def describe_selector(selector: Mapping[str, Any]) -> str:
    """``{"event": "activity.completed", "activity": "take", "process": "p"}`` →
    ``the completion of activity take (workflow p)``."""
    event = str(selector.get("event") or "?")
    process, activity = selector.get("process"), selector.get("activity")
    if event.startswith("process."):
        what = f"workflow {process}" if process else "any workflow"
        return f"the {_EVENTS.get(event, event + ' of')} {what}"
    where = f" (workflow {process})" if process else ""
    if activity:
        verb = _EVENTS.get(event)
        return (f"the {verb} activity {activity}{where}" if verb
                else f"a {event} event of activity {activity}{where}")
    verb = _EVENTS.get(event)
    target = f"workflow {process}" if process else "any workflow"
    return f"the {verb} an activity of {target}" if verb and event.startswith("activity.") \
        else f"a {event} event" + (f" in workflow {process}" if process else "")


def _bare(phrase: str) -> str:
    """A selector's words without their article, to follow "every" or "the first": they
    start with "the " (an event of a named kind) or "a " (any other event)."""
    for article in ("the ", "a "):
        if phrase.startswith(article):
            return phrase[len(article):]
    return phrase


def describe_metric(definition: Mapping[str, Any]) -> str:
    """One metric in words: its description from the spec, then how it is computed."""
    kind = definition.get("kind")
    own = str(definition.get("description") or "").strip()
    if own and not own.endswith((".", "!", "?")):
        own += "."
    if kind == "count":
        select = definition.get("select")
        how = (f"Counted in the trace: every {_bare(describe_selector(select))}, per simulated "
               "user over the whole run." if select else "A count of trace events per "
               "simulated user over the whole run.")
    elif kind == "duration":
        start, end = definition.get("start"), definition.get("end")
        unit = definition.get("unit") or "s"
        if start and end:
            which = "first" if (start.get("which") or "first") == "first" else "last"
            how = (f"Measured in the trace: time ({unit}) from the {which} "
                   f"{_bare(describe_selector(start))} to "
                   f"{describe_selector(end)}, within the same workflow instance; one "
                   "observation per instance in which both happen.")
        else:
            how = f"A time ({unit}) between two trace events within one workflow instance."
    elif kind == "ratio":
        num, den = definition.get("numerator"), definition.get("denominator")
        how = (f"{num} divided by {den}, both summed over all users (Σ {num} / Σ {den})."
               # the spec's declaration, as the tables read it (tables.in_percent)
               + (" Shown as a percentage."
                  if definition.get("proportion") is True else ""))
    else:
        how = ""
    return " ".join(part for part in (own, how) if part)


# ------------------------------------------------------------------------------ user model

def _seconds(value: float) -> str:
    return f"{value:.3g} s"


def describe_distribution(dist: Distribution) -> str:
    """``lognormal (median 60 s, sigma 0.6), mean 71.8 s``; a constant is just its value."""
    params = dist.to_params()
    kind = str(params.get("kind", type(dist).__name__.lower()))
    if kind == "constant":
        return _seconds(float(params.get("value", dist.mean)))
    shown = ", ".join(f"{k} {_seconds(v) if k in _TIME_KEYS else f'{v:.3g}'}"
                      if isinstance(v, (int, float)) and not isinstance(v, bool)
                      else f"{k} {v}"
                      for k, v in params.items() if k not in {"kind", "base", "values"})
    base = getattr(dist, "base", None)
    if kind == "with_tail" and base is not None:
        return (f"{describe_distribution(base)} plus an exponential slow tail "
                f"(mean {_seconds(float(params['tau']))})")
    if kind == "empirical":
        shown = f"{len(params.get('values') or [])} observed values"
    try:
        mean = f", mean {_seconds(dist.mean)}"
    except (AttributeError, ValueError, TypeError):
        mean = ""
    return f"{kind} ({shown}){mean}" if shown else f"{kind}{mean}"


_TIME_KEYS = {"value", "median", "mean", "mu", "scale", "low", "high", "mode", "min", "max",
              "tau", "loc", "sigma_s", "sd", "minimum", "maximum", "a", "b", "c"}


def _pct(p: float) -> str:
    return f"{p * 100:.3g} %"


def _errors(model: ActivityModel) -> str:
    parts = []
    if model.omission is not None:
        parts.append(f"omitted with probability {_pct(model.omission.probability)} "
                     f"({model.omission.reason})")
    if model.commission is not None:
        c = model.commission
        wrong = ", ".join(c.alternatives) or "another alternative"
        parts.append(f"wrong choice ({wrong}) with probability {_pct(c.probability)}"
                     + (f", at most {c.max_per_instance} per instance"
                        if c.max_per_instance else ""))
    if model.repetition is not None:
        parts.append(f"done twice with probability {_pct(model.repetition.probability)}")
    if model.delay is not None:
        parts.append(f"starts late with probability {_pct(model.delay.probability)} by "
                     f"{describe_distribution(model.delay.duration)}")
    if model.intended is not None and model.commission is None:
        parts.append(f"chooses {model.intended}")
    if model.probabilities:
        parts.append("chooses " + ", ".join(f"{a} {_pct(p)}" for a, p in model.probabilities))
    return "; ".join(parts) or "none"


def user_model_rows(model: UserModel) -> list[tuple[str, str, str, str]]:
    """Per activity the model covers: (activity, duration, errors, source)."""
    rows = [(name, describe_distribution(a.duration), _errors(a), _sources(a))
            for name, a in model.activities.items()]
    if model.default is not None:
        d = model.default
        rows.append(("any other activity", describe_distribution(d.duration), _errors(d),
                     _sources(d)))
    return rows


def _sources(model: ActivityModel) -> str:
    """Where the activity's numbers come from: its own source and its errors' sources."""
    found = [model.source]
    for part in (model.omission, model.commission, model.repetition, model.delay):
        found.append(getattr(part, "source", None))
    unique = list(dict.fromkeys(str(s).rstrip(".") for s in found if s))
    return "; ".join(unique) or "–"


def can_do_wrongly(model: UserModel, activity: str) -> bool | None:
    """Whether a user of ``model`` can do ``activity`` wrongly: a wrong choice or a slip,
    the only wrong actions a user is counted for, both its ``commission`` (in the typical
    model or any subgroup's: a person's drawn values and modifiers change probabilities,
    never add one). None when some model does not cover the activity (not known here)."""
    models = [model, *(g.model for g in (model.population.subgroups
                                         if model.population is not None else ()))]
    if not all(m.covers(activity) for m in models):
        return None
    return any(m.activity(activity).commission is not None for m in models)


def user_model_notes(model: UserModel) -> list[str]:
    """The model's assumptions besides the per-activity table, in sentences."""
    notes = []
    if model.description:
        notes.append(model.description.rstrip(".") + ".")
    if model.source:
        notes.append(f"Source: {model.source.rstrip('.')}.")
    if model.busy is not None:
        b = model.busy
        ignored = ("every other prompt" if b.ignore is None
                   else ", ".join(sorted(b.ignore)) or "nothing")
        # in the spec's terms (a workflow instance), not the dispenser's (a dose): a stove
        # guard's report said "for one dose" too
        notes.append(f"While busy with {', '.join(sorted(b.engaged))} in one workflow "
                     f"instance, the user ignores {ignored} from other instances"
                     + (f" ({b.source.rstrip('.')})." if b.source else "."))
    for modifier in model.modifiers:
        changes = []
        if modifier.duration_factor != 1.0:
            changes.append(f"durations × {modifier.duration_factor:g}")
        if modifier.tail_fraction:
            changes.append(f"a slow tail of {modifier.tail_fraction:g} × each mean duration")
        if modifier.notice_factor != 1.0:
            changes.append(f"chance of noticing a prompt × {modifier.notice_factor:g}")
        notes.append(f"Modifier {modifier.name}: {', '.join(changes) or 'no change'} "
                     "(already applied in the table)"
                     + (f"; {modifier.source.rstrip('.')}." if modifier.source else "."))
    routine = model.routine
    if not routine.is_trivial:
        for w in routine.windows:
            # w.start/w.end are seconds after midnight: shown as the clock times they are
            notes.append(f"Routine window {w.name} ({time_of_day(w.start)}–"
                         f"{time_of_day(w.end)}): noticing × "
                         f"{w.notice_factor:g}, durations × {w.duration_factor:g}"
                         + (f"; {w.source.rstrip('.')}." if w.source else "."))
        d = routine.drift
        if not d.is_identity:
            notes.append(f"Drift per day: noticing × {d.notice_factor_per_day:g} (not below "
                         f"{d.min_notice_factor:g}), durations × "
                         f"{d.duration_factor_per_day:g} (not below "
                         f"{d.min_duration_factor:g})"
                         + (f"; {d.source.rstrip('.')}." if d.source else "."))
    if model.population is not None:
        notes.append("The table shows the typical user (the file without its variation): "
                     "the simulated users differ from it and from each other as the "
                     "population below says.")
    else:
        notes.append("Every simulated user has these same parameters and differs from the "
                     "others only by chance (each draws from their own random streams): the "
                     "spread between users in this report is chance variation, not "
                     "differences between people.")
    return notes


# ------------------------------------------------------------------------------ population

def variation_rows(population: Population) -> list[tuple[str, ...]]:
    """What differs by person, as the file declares it: (subgroup, share, parameter, per-user
    distribution, mean, sd, 5-95 % range, source)."""
    rows: list[tuple[str, ...]] = []
    for group in population.subgroups:
        label = group.name or "all users"
        share = f"{group.share * 100:.3g} %"
        if not group.varied:
            rows.append((label, share, "–", "nothing varies", "–", "–", "–",
                         group.source or "–"))
        for varied in group.varied:
            d = varied.distribution
            rows.append((label, share, varied.name, d.describe(), f"{d.mean:.4g}",
                         f"{d.sd:.4g}", f"{d.quantile(0.05):.4g} – {d.quantile(0.95):.4g}",
                         varied.source or "–"))
    return rows


def correlation_rows(population: Population) -> list[tuple[str, ...]]:
    """The stated correlations: (subgroup, parameters, stated, the Gaussian copula's r,
    source)."""
    rows: list[tuple[str, ...]] = []
    for group in population.subgroups:
        for c in group.correlations:
            rows.append((group.name or "all users", f"{c.first} ~ {c.second}",
                         f"{c.kind} {c.value:g}", f"{c.r:.3f}", c.source or "–"))
    return rows


def population_notes(population: Population) -> list[str]:
    """The subgroups in sentences (what each is, where it comes from)."""
    notes = []
    for group in population.subgroups:
        if group.name is None:
            continue
        words = group.description.rstrip(".") or f"model {group.model.name}"
        notes.append(f"Subgroup {group.name} ({group.share * 100:.3g} % of users): {words}"
                     + (f" (source: {group.source.rstrip('.')})." if group.source else "."))
    if population.after:
        notes.append("Composed on top of the population, applied to each person after the "
                     "draw: " + ", ".join(m.name for m in population.after) + ".")
    notes.append("Each user's subgroup and parameters are drawn once, from a random stream of "
                 "their own (the same user of the same seed is the same person in every run "
                 "and in both designs of a comparison); parameters are correlated through a "
                 "Gaussian copula with the stated rank correlations.")
    return notes
