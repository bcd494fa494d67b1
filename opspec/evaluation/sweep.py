"""Sweeps: ``opspec evaluate SPEC --sweep PARAM=v1,v2,…`` runs one design per value of a spec or
user-model parameter (:mod:`opspec.evaluation.parameters` names them) on the same simulated
users — the machinery of ``--compare``: each value is a design of the plan, and user ``u`` of
every design draws from the streams of ``(seed, u)`` (common random numbers) — then gives, per
value, every metric with its interval and the paired difference against the first value, a
figure of each metric against the parameter, and the values that meet stated targets
(:mod:`opspec.evaluation.targets`), for the mean and for a share of users.

Designs are labelled ``A`` (the first value, the reference every difference is taken against)
and ``S1``, ``S2``, … for the others; the sweep (parameter, values) is stored in the run table
under ``sweep``, so ``--resume`` finishes and reports it like any run.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError
from opspec.evaluation.no_spread_notes import figure_marks, marked
from opspec.evaluation.parameters import Parameter, describe_value, parse_value, resolve
from opspec.evaluation.plan import Design, EvaluationPlan
from opspec.evaluation.store import ResultStore

# the tables, as the terminal and the report show them, are sweep_tables' (names kept here)
from opspec.evaluation.sweep_tables import (  # noqa: F401
    SWEEP_HEADERS,
    _cells,
    _estimate,
    _note,
    metric_table,
    print_sweep,
    target_table,
)
from opspec.evaluation.targets import Target, parse_target, share_verdict, verdict
from opspec.statistics.clustered import unpaired_difference
from opspec.statistics.no_spread import no_spread
from opspec.statistics.percentiles import nearest_rank

__all__ = ["Sweep", "describe_parameters", "plan_sweep", "print_sweep", "report_sections",
           "summarise_sweep"]

#: how ``--sweep list`` (or a value list of one) is spelled
LIST = "list"


@dataclass(frozen=True, slots=True)
class SweepValue:
    """One value of the swept parameter: its design label, the value, and how it reads."""

    design: str
    value: Any
    text: str


@dataclass(frozen=True, slots=True)
class Sweep:
    """The swept parameter (name, unit, what it is, its value in the spec or model) and its
    values, first the reference."""

    parameter: str
    unit: str
    what: str
    current: Any
    values: tuple[SweepValue, ...]

    @property
    def labels(self) -> list[str]:
        return [v.design for v in self.values]

    def to_json(self) -> dict[str, Any]:
        return {"parameter": self.parameter, "unit": self.unit, "what": self.what,
                "current": self.current,
                "values": [{"design": v.design, "value": v.value, "text": v.text}
                           for v in self.values]}

    @classmethod
    def from_json(cls, doc: Mapping[str, Any]) -> Sweep:
        return cls(str(doc["parameter"]), str(doc["unit"]), str(doc.get("what") or ""),
                   doc.get("current"), tuple(SweepValue(str(v["design"]), v["value"],
                                                        str(v["text"]))
                                             for v in doc["values"]))


def label(index: int) -> str:
    """The design label of the ``index``-th value: ``A`` for the first (the reference)."""
    return "A" if index == 0 else f"S{index}"


def _loaded(plan: EvaluationPlan) -> tuple[Any, Any]:
    """The spec's package and the user model (None without one) of ``plan``'s design A."""
    from opspec.runs import load

    package = load(plan.design("A").spec).package
    model = None
    if plan.user_model is not None:
        from opspec.usermodels import load_user_model

        model = load_user_model(plan.user_model)
    return package, model


def describe_parameters(plan: EvaluationPlan) -> str:
    """Every sweepable parameter of the plan's spec and user model, with its unit and current
    value (``opspec evaluate SPEC --sweep list``)."""
    from opspec.evaluation.parameters import UNITS, sweepable
    from opspec.evaluation.tables import table

    package, model = _loaded(plan)
    found = sweepable(package, model)
    rows = [(p.name, p.unit, describe_value(p, p.current), p.what) for p in found.values()]
    head = (f"sweepable parameters of {plan.design('A').spec}"
            + (f" and the user model {plan.user_model}" if plan.user_model else "") + ":")
    units = "\n".join(f"  {unit}: {text}" for unit, text in UNITS.items())
    return "\n".join([head, "", *table(("parameter", "unit", "now", "what"), rows), "",
                      "values are read in the parameter's unit:", units])


def plan_sweep(plan: EvaluationPlan, name: str, texts: Sequence[str]) -> tuple[
        EvaluationPlan, Sweep]:
    """``plan`` with one design per value of the parameter ``name`` (read from ``texts``),
    and the sweep; an EvaluationError for an unknown name, a value that does not parse, a
    value given twice, or a plan that already compares two specs."""
    if len(plan.designs) > 1:
        raise EvaluationError("--sweep and --compare cannot be combined",
                              hint="a sweep compares every value with the first; to sweep "
                              "two designs, run one sweep per spec")
    package, model = _loaded(plan)
    parameter: Parameter = resolve(name, package, model, where=(
        f"{plan.design('A').spec}" + (f" and {plan.user_model}" if plan.user_model else "")))
    values: list[SweepValue] = []
    for index, text in enumerate(texts):
        value = parse_value(parameter, text)
        same = next((v for v in values if v.value == value), None)
        if same is not None:
            raise EvaluationError(f"--sweep {parameter.name}: {text.strip()!r} is the same "
                                  f"value as {same.text!r}", hint="give each value once")
        values.append(SweepValue(label(index), value, describe_value(parameter, value)))
    if len(values) < 2:
        raise EvaluationError(f"--sweep {parameter.name}: give at least two values "
                              "(PARAM=v1,v2,…)", hint="a sweep compares values with the "
                              "first; for one value, a plain run does")
    a = plan.design("A")
    kept = tuple(p for p in a.parameters if p[0] != parameter.name)    # --param values
    designs = tuple(Design(v.design, a.spec, a.sha256, (*kept, (parameter.name, v.value)))
                    for v in values)
    sweep = Sweep(parameter.name, parameter.unit, parameter.what, parameter.current,
                  tuple(values))
    return replace(plan, designs=designs), sweep


# --------------------------------------------------------------------------- the summary


def _differences(store: ResultStore, reference: str, design: str, level: float
                 ) -> dict[str, dict[str, Any]]:
    from opspec.evaluation.summary import compare_designs, metric_definitions, user_pairs

    out = compare_designs(store, reference, design, level)
    for definition in metric_definitions(store, reference):
        entry = out.get(definition["name"])
        if entry is None:
            continue
        pa = dict(user_pairs(store, reference, definition))
        pb = dict(user_pairs(store, design, definition))
        users = sorted(set(pa) & set(pb))
        # what the difference's interval would be on independent users (Welch): beside the
        # paired interval it shows what common random numbers gained
        unpaired = unpaired_difference([pa[u] for u in users], [pb[u] for u in users], level)
        entry["unpaired_ci95"] = unpaired.ci
        entry["unpaired_ci95_method"] = unpaired.method
        # no width when each value's users were all alike, as a ci95's (docs/evaluation.md)
        entry["unpaired_ci95_no_spread"] = no_spread(unpaired.ci, len(users), level)
    return out


def _own_values(store: ResultStore, design: str, definition: Mapping[str, Any],
                users: set[int] | None = None) -> list[float]:
    """Each user's own value of a metric: their total of a count, their rate, their mean
    duration (users without a denominator or observations left out)."""
    from opspec.evaluation.summary import user_pairs

    pairs = [p for _, p in user_pairs(store, design, definition, users)]
    if definition["kind"] == "count":
        return [y for y, _ in pairs]
    return [y / n for y, n in pairs if n > 0]


def _per_user_quantile(values: Sequence[float], share: float, below: bool) -> float | None:
    """The value ``share`` of the users stay on the good side of: the smallest value at or
    below which at least ``share`` of the users' own values lie (a target asking for small
    values), or the largest at or above which they lie (else). No interpolation: a user's
    own rate over a short run takes few values (0 or 3.6 % of 28 doses), and a quantile
    between them would describe nobody."""
    if not values:
        return None
    return nearest_rank(sorted(values), share, from_top=not below)


def _target_summary(store: ResultStore, sweep: Sweep, target: Target,
                    per_value: Mapping[str, Mapping[str, Any]], share: float | None,
                    subgroups: Sequence[str], level: float) -> dict[str, Any]:
    from opspec.evaluation.summary import metric_definitions, subgroup_users
    from opspec.statistics import rate_interval

    definition = next(d for d in metric_definitions(store, "A") if d["name"] == target.metric)
    rows = []
    for value in sweep.values:
        summary = per_value[value.design]["metrics"][target.metric]
        estimate, ci = _estimate(summary)
        row: dict[str, Any] = {"design": value.design, "value": value.value,
                               "text": value.text, "estimate": estimate, "ci95": ci,
                               "ci95_no_spread": summary.get("ci95_no_spread"),
                               "verdict": verdict(target, ci, alike=marked(summary))}
        if share is not None:
            own = _own_values(store, value.design, definition)
            hit = sum(1 for v in own if target.holds(v))
            ci_share = (list(rate_interval(hit, len(own), level,
                                           method="clopper-pearson")[1:]) if own else None)
            row["users"] = {
                "users": len(own), "meeting": hit,
                "share": hit / len(own) if own else None, "share_ci95": ci_share,
                "quantile": _per_user_quantile(own, share, target.below),
                "verdict": share_verdict(ci_share, share)}
        if subgroups:
            row["by_subgroup"] = {}
            for group in subgroups:
                s = per_value[value.design]["subgroups"][group][target.metric]
                g_estimate, g_ci = _estimate(s)
                entry: dict[str, Any] = {"estimate": g_estimate, "ci95": g_ci,
                                         "verdict": verdict(target, g_ci,
                                                            alike=marked(s))}
                if share is not None:
                    own = _own_values(store, value.design, definition,
                                      subgroup_users(store, value.design, group))
                    hit = sum(1 for v in own if target.holds(v))
                    entry["users_share"] = hit / len(own) if own else None
                row["by_subgroup"][group] = entry
        rows.append(row)
    doc: dict[str, Any] = {**target.to_json(), "users_share": share, "values": rows,
                           "meets": [r["text"] for r in rows if r["verdict"] == "meets"],
                           "undecided": [r["text"] for r in rows
                                         if r["verdict"] == "undecided"]}
    doc["answer"] = _answer(sweep, target, rows, "verdict", None)
    if share is not None:
        doc["users_meets"] = [r["text"] for r in rows if r["users"]["verdict"] == "meets"]
        doc["users_undecided"] = [r["text"] for r in rows
                                  if r["users"]["verdict"] == "undecided"]
        doc["users_answer"] = _answer(sweep, target, rows, "users", share)
    return doc


def _answer(sweep: Sweep, target: Target, rows: Sequence[Mapping[str, Any]], key: str,
            share: float | None) -> str:
    """The target's answer in one plain sentence."""
    def verdict_of(row: Mapping[str, Any]) -> str:
        return str(row[key]["verdict"] if key == "users" else row[key])

    who = (f"for {100 * share:.4g} % of users (each user's own {target.metric} over the run)"
           if share is not None else "on average")
    meets = [r["text"] for r in rows if verdict_of(r) == "meets"]
    undecided = [r["text"] for r in rows if verdict_of(r) == "undecided"]
    head = f"{target.describe()} {who}: "
    if meets:
        text = (head + f"met with {sweep.parameter} = {', '.join(meets)}"
                + (" (every value)" if len(meets) == len(rows) else ""))
        if undecided:
            text += f"; undecided at {', '.join(undecided)} ({_why(rows, key)})"
        return text + "."
    fails = [r["text"] for r in rows if verdict_of(r) == "fails"]
    if undecided:
        return (head + f"no value is shown to meet it; undecided at {', '.join(undecided)} "
                f"({_why(rows, key, '95 % ')}: more users would tell)"
                + (f"; failed at {', '.join(fails)}" if fails else "") + ".")
    return head + f"no value of {sweep.parameter} meets it; every value fails it."


def _why(rows: Sequence[Mapping[str, Any]], key: str, level: str = "") -> str:
    """Why the verdicts on the target's interval are undecided, in the answer's words."""
    alike = key == "verdict" and any(r["verdict"] == "undecided" and marked(r) for r in rows)
    return (f"the {level}interval contains the target"
            + (", or has no width because the users were all alike" if alike else ""))


def summarise_sweep(store: ResultStore, sweep: Sweep, days: float,
                    targets: Sequence[str] = (), users_share: float | None = None,
                    level: float = 0.95) -> dict[str, Any]:
    """The sweep's results (``sweep`` of ``opspec evaluate --json``): per value every metric
    (as :func:`opspec.evaluation.summary.summarise_design`) and the paired difference against
    the first value (with the unpaired interval beside it), per subgroup for a population,
    and the answer to each target."""
    from opspec.evaluation.summary import (
        has_population,
        metric_definitions,
        summarise_design,
    )

    definitions = metric_definitions(store, "A")
    parsed = [parse_target(t, definitions) for t in targets]
    subgroups: list[str] = []
    if has_population(store):
        subgroups = [str(g) for g, _ in store.query(
            "SELECT subgroup, MIN(rowid) FROM person WHERE design = 'A' AND subgroup IS NOT "
            "NULL GROUP BY subgroup ORDER BY MIN(rowid)")]
    per_value: dict[str, dict[str, Any]] = {}
    values = []
    for value in sweep.values:
        entry: dict[str, Any] = {
            "design": value.design, "value": value.value, "text": value.text,
            "metrics": summarise_design(store, value.design, days, level),
            "difference": (None if value.design == "A"
                           else _differences(store, "A", value.design, level))}
        if subgroups:
            entry["subgroups"] = {g: summarise_design(store, value.design, days, level,
                                                      subgroup=g) for g in subgroups}
        per_value[value.design] = entry
        values.append(entry)
    answers = [_target_summary(store, sweep, t, per_value, users_share, subgroups, level)
               for t in parsed]
    parameter = Parameter(sweep.parameter, sweep.unit, sweep.current, sweep.what)
    doc: dict[str, Any] = {**sweep.to_json(), "reference": sweep.values[0].text,
                           "current_text": describe_value(parameter, sweep.current),
                           "users_share": users_share, "values": values,
                           "targets": answers}
    if len(answers) > 1:
        every = [v.text for v in sweep.values
                 if all(v.text in a["meets"] for a in answers)]
        doc["meets_every_target"] = every
        if users_share is not None:
            doc["users_meet_every_target"] = [
                v.text for v in sweep.values if all(v.text in a["users_meets"]
                                                    for a in answers)]
    return doc


# ---------------------------------------------------------------------------- the table


# --------------------------------------------------------------------------- the report


def _numeric_axis(summary: Mapping[str, Any]) -> bool:
    return all(isinstance(v["value"], (int, float)) and not isinstance(v["value"], bool)
               for v in summary["values"])


def report_sections(summary: Mapping[str, Any], figures: Path, users: int) -> list[Any]:
    """The report's sweep sections: what was swept, the targets' answers, the figure of each
    metric against the parameter with its interval band, and the tables."""
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table
    from opspec.evaluation.tables import in_percent

    values = summary["values"]
    numeric = _numeric_axis(summary)
    xs = [float(v["value"]) if numeric else float(i) for i, v in enumerate(values)]
    series: dict[str, tuple[list[float | None], list[float | None], list[float | None]]] = {}
    percent: dict[str, bool] = {}
    units: dict[str, str] = {}
    for metric, first in values[0]["metrics"].items():
        est, low, high = [], [], []
        for v in values:
            e, (lo, hi) = _estimate(v["metrics"].get(metric) or {})
            est.append(e)
            low.append(lo)
            high.append(hi)
        series[metric] = (est, low, high)
        percent[metric] = in_percent(first)
        units[metric] = (first.get("unit") or "s") if first["kind"] == "duration" else (
            "per user" if first["kind"] == "count" else "")
    lines: dict[str, list[tuple[str, float]]] = {}
    per_user: dict[str, tuple[str, list[float | None]]] = {}
    for answer in summary["targets"]:
        lines.setdefault(answer["metric"], []).append((answer["target"],
                                                       float(answer["threshold"])))
        share = answer.get("users_share")
        if share is not None:
            side = "p" + (f"{100 * share:.4g}" if answer["op"].startswith("<")
                          else f"{100 * (1 - share):.4g}")
            per_user[answer["metric"]] = (
                f"{side} of the users' own values",
                [row["users"]["quantile"] for row in answer["values"]])
    axis = f"{summary['parameter']} ({summary['unit']})"
    # a band of no width from users all alike: marked in the figure and its caption
    alike = figure_marks({m: [v["metrics"].get(m) for v in values] for m in series})
    image = plots.sweep_figure(axis, xs, [v["text"] for v in values], series,
                               figures / "sweep.png", percent=percent, units=units,
                               targets=lines, per_user=per_user, **alike)
    findings = [a["answer"] for a in summary["targets"]]
    findings += [a["users_answer"] for a in summary["targets"] if a.get("users_answer")]
    sections = [Section(f"Sweep of {summary['parameter']}", paragraphs=(
        (f"{summary['parameter']} is the {summary['what']} (now "
         f"{summary.get('current_text') or summary.get('current')} in the spec or model). "
         f"Each of its {len(values)} values ran on the same {users:,} simulated users with "
         "the same random streams (common random numbers), so differences between values "
         "are not drowned in user-to-user noise: each difference is paired, user by user, "
         f"against the first value ({summary['reference']}). The sections after this one "
         f"describe the run at the first value."),),
        items=tuple(findings), images=(image,), captions=(
            ("Each metric against the parameter: the line is the estimate, the band its 95 % "
             "confidence interval (each metric on its own scale); dashed lines are the "
             "targets, dotted lines the per-user quantile a share-of-users target is "
             "judged by" + (f". {alike['no_spread_note']}" if alike else "")),))]
    tables = [Table(SWEEP_HEADERS, tuple(metric_table(summary, metric)),
                    f"{metric}: per value, and the paired difference against "
                    f"{summary['reference']} (* the interval excludes 0)")
              for metric in values[0]["metrics"]]
    for answer in summary["targets"]:
        headers, rows = target_table(answer, summary)
        tables.append(Table(headers, tuple(rows), f"Target {answer['target']}"))
    sections.append(Section(f"Sweep of {summary['parameter']}: tables", paragraphs=(
        ("A target is met when the whole 95 % interval lies on its side, failed when the "
         "whole interval lies on the other side, and undecided when the interval contains "
         "it (more users would tell). For a share of users, each user's own value over the "
         "simulated period is judged, and the share of users meeting the target (with its "
         "exact Clopper-Pearson interval) is compared with the share asked for; a longer "
         "period measures each user's own rate more exactly. 'paired/unpaired width' is the "
         "width of the paired interval over the width the interval would have with "
         "independent users for each value."), *filter(None, [_note(summary)])),
        tables=tuple(tables)))
    return sections


# ---------------------------------------------------------------------- the command's side


def check_targets(targets: Sequence[str], users_share: float | None,
                  definitions: Sequence[Mapping[str, Any]], sweep: Sweep | None) -> None:
    """Refuse, before anything runs, targets without a sweep and targets that do not
    parse against the metrics the spec declares."""
    if (targets or users_share is not None) and sweep is None:
        raise EvaluationError("--target and --target-users answer a sweep",
                              hint="add --sweep PARAM=v1,v2,… (docs/evaluation.md, Sweeps)")
    if users_share is not None and not targets:
        raise EvaluationError("--target-users needs a --target (e.g. --target "
                              "\"missed_rate < 1%\")")
    for text in targets:
        parse_target(text, definitions)


def resumed_sweep(store: ResultStore, plan: EvaluationPlan,
                  option: tuple[str, Sequence[str]] | None) -> Sweep | None:
    """The stored run's sweep (None for a run without one); an EvaluationError when
    ``--sweep`` is given with ``--resume`` and differs from it."""
    stored = store.get("sweep")
    sweep = Sweep.from_json(stored) if stored else None
    if option is None:
        return sweep
    if sweep is None:
        raise EvaluationError(f"{store.folder} holds a run without a sweep; cannot resume it "
                              f"with --sweep {option[0]}",
                              hint="resume without --sweep, or start a new run with another "
                              "--out")
    _, given = plan_sweep(replace(plan, designs=plan.designs[:1]), option[0], option[1])
    if (given.parameter, [v.value for v in given.values]) != (
            sweep.parameter, [v.value for v in sweep.values]):
        raise EvaluationError(
            f"{store.folder} holds a sweep of {sweep.parameter} = "
            f"{', '.join(v.text for v in sweep.values)}; cannot resume it with --sweep "
            f"{given.parameter} = {', '.join(v.text for v in given.values)}",
            hint="resume with the stored sweep (or without --sweep), or start a new run "
            "with another --out")
    return sweep
