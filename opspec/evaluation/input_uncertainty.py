"""Input uncertainty: an evaluation's intervals when the user model was fitted, not known.

``opspec evaluate --input-uncertainty B`` (a user model written by ``opspec fit``, whose
``[uncertainty]`` table holds bootstrap redraws of its parameters:
:mod:`opspec.usermodels.uncertainty`) runs, beside the ordinary evaluation at the point
estimates, ``B`` *parameter draws*, each on a batch of ``m`` users of its own (``m`` =
``--users-per-draw``). This is the direct bootstrap of Barton & Schruben (2001, "Resampling
methods for input modeling", Proc. Winter Simulation Conference) with the variance split of
Ankenman & Nelson (2012, "A quick assessment of input uncertainty", Proc. WSC; Barton,
Nelson & Xie 2014, "Quantifying input uncertainty via simulation confidence intervals",
INFORMS J. Computing 26(1)):

* each batch ``b`` gives the metric's estimate ``θ_b`` (the same cluster-robust ratio as the
  ordinary summary) and its simulation variance ``s_b²``;
* the variance of ``θ_b`` over batches is the parameters' variance plus the batches'
  simulation noise (a random-effects model), so the **parameter variance** is
  ``σ_I² = var_b(θ_b) − mean_b(s_b²)`` (at least 0);
* the interval **with parameter uncertainty** is ``θ̂ ± t·sqrt(se² + σ_I²)`` around the
  ordinary estimate ``θ̂`` (whose simulation variance is ``se²``), t on the
  Welch-Satterthwaite degrees of freedom of the two parts (U − 1 and B − 1); never narrower
  than the ordinary interval;
* the **parameter share** ``σ_I² / (se² + σ_I²)``: how much of the widened interval's
  variance the fitted parameters cause, the rest being simulation noise — more users shrink
  only the rest;
* the direct bootstrap's percentile interval of the ``θ_b`` is reported too (it also holds
  the batches' simulation noise: conservative when ``m`` is small, crude below B = 40).

Users and streams: user ``u`` of a run seeded ``S`` always draws from ``(S, u)``
(:mod:`opspec.evaluation.replication`). The ordinary users are ``0 .. U−1`` as ever, so the
ordinary results are byte for byte those of a run without ``--input-uncertainty``; draw
``b`` (1-based) runs users ``U + (b−1)·m .. U + b·m − 1``, stored under the design label
``A~draws`` (``B~draws`` with ``--compare``: the same users and the same draw, so paired
differences keep their common random numbers). A user's draw depends on ``(U, m, u)`` only:
the same seed gives the same results whatever the number of workers.
"""

from __future__ import annotations

import math
import statistics as pystats
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import IO, Any

from opspec.errors import EvaluationError, OpspecError
from opspec.evaluation.no_spread_notes import no_spread_note, with_mark
from opspec.statistics.clustered import paired_variance, ratio_variance
from opspec.statistics.no_spread import no_spread
from opspec.statistics.percentiles import linear

__all__ = ["SUFFIX", "base_design", "check_draws", "draw_of", "draw_users", "draws_label",
           "print_input_uncertainty", "run_draw_users", "summarise_input_uncertainty"]

#: the store's design label of design X's parameter draws is X + SUFFIX
SUFFIX = "~draws"
#: users per draw when --users-per-draw is not given: the ordinary run's users spread over
#: the draws (so the draws cost about as much as the ordinary run), at least this many
MIN_USERS_PER_DRAW = 10


def draws_label(label: str) -> str:
    return f"{label}{SUFFIX}"


def base_design(label: str) -> str | None:
    """``A`` for ``A~draws``; None for an ordinary design label."""
    return label[:-len(SUFFIX)] if label.endswith(SUFFIX) else None


def default_users_per_draw(users: int, draws: int) -> int:
    return max(MIN_USERS_PER_DRAW, math.ceil(users / max(draws, 1)))


def draw_users(plan: Any) -> range:
    """The user indices of every draw's batch (after the ordinary users)."""
    return range(plan.users, plan.users + plan.input_uncertainty * plan.users_per_draw)


def draw_of(users: int, per_draw: int, user: int) -> int:
    """The draw (1-based) user ``user`` runs, ``users`` being the ordinary users."""
    return 1 + (user - users) // per_draw


# ---------------------------------------------------------------------------- checking

def check_draws(plan: Any) -> Any:
    """The parameter draws of the plan's user model, checked against what the plan asks
    (an EvaluationError saying what to do otherwise)."""
    from opspec.usermodels.uncertainty import read_parameter_draws

    if plan.input_uncertainty < 2:
        raise EvaluationError(f"--input-uncertainty needs at least 2 draws, not "
                              f"{plan.input_uncertainty}",
                              hint="20 to 100 draws is usual (the variance between draws "
                              "needs several)")
    if plan.users_per_draw < 2:
        raise EvaluationError(f"--users-per-draw must be at least 2, not "
                              f"{plan.users_per_draw}",
                              hint="each draw's simulation noise is estimated from its users")
    if plan.user_model is None:
        raise EvaluationError("--input-uncertainty needs a fitted user model",
                              hint="fit one with `opspec fit TRACES -o model.users.toml` and "
                              "give it with --user-model")
    if any(d.parameters for d in plan.designs):
        raise EvaluationError("--input-uncertainty and --sweep cannot be combined",
                              hint="evaluate the value of interest with --input-uncertainty "
                              "on its own")
    found = read_parameter_draws(plan.user_model)
    if found is None:
        raise EvaluationError(
            f"{plan.user_model} holds no parameter draws (no [uncertainty] table)",
            hint="fit the model with `opspec fit` (it writes 200 draws; --draws B for "
            "more), or drop --input-uncertainty")
    draws, _ = found
    if plan.input_uncertainty > draws.count:
        raise EvaluationError(
            f"--input-uncertainty {plan.input_uncertainty}: {draws.path} holds "
            f"{draws.count} parameter draws", hint=f"ask for at most {draws.count}, or fit "
            f"again with --draws {plan.input_uncertainty}")
    return draws


# ----------------------------------------------------------------------------- running

_DRAWN: dict[tuple[Any, ...], Any] = {}


def _context(plan: Mapping[str, Any], base: Mapping[str, Any], draw: int) -> Any:
    """The replication context of design ``base`` with the user model of draw ``draw``
    (loaded once per process and draw)."""
    from opspec.evaluation.replication import prepare
    from opspec.runs import User
    from opspec.usermodels.uncertainty import drawn_model, read_parameter_draws

    ref = str(plan["user_model"])
    context = prepare(base["spec"], base["sha256"], ref, plan.get("engine") or {}, (),
                      plan.get("branches") or None)
    key = (id(context), ref, draw)
    found = _DRAWN.get(key)
    if found is None:
        located = _DRAWN.get((ref,))
        if located is None:
            located = _DRAWN[(ref,)] = read_parameter_draws(ref)
        if located is None:
            raise EvaluationError(f"{ref} holds no parameter draws")
        draws, index = located
        model = drawn_model(ref, draws, index, draw)
        describe = context.user.describe if context.user is not None else None
        found = _DRAWN[key] = replace(context, user=User.model(model, describe))
    return found


def run_draw_users(plan: Mapping[str, Any], label: str, users: Sequence[int]) -> list[Any]:
    """Worker entry point for the users of ``label`` (``A~draws``): each user simulated with
    their draw's model, on their own streams (no traces are kept)."""
    from opspec.evaluation.replication import ReplicationRecord, run_user
    from opspec.run_rules import seconds_of_days

    base_label = base_design(label)
    base = next(d for d in plan["designs"] if d["label"] == base_label)
    horizon = seconds_of_days(float(plan["days"]))
    ordinary, per_draw = int(plan["users"]), int(plan["users_per_draw"])
    records = []
    for u in users:
        draw = draw_of(ordinary, per_draw, u)
        try:
            context = _context(plan, base, draw)
        except OpspecError as error:
            records.append(ReplicationRecord(label, u, "failed", error=f"draw {draw}: "
                                             f"{error}"))
            continue
        records.append(run_user(context, label, u, seed=int(plan["seed"]), horizon=horizon,
                                keep_trace=False))
    return records


# --------------------------------------------------------------------------- summarising

def _combine(estimate: float | None, ordinary: Sequence[float | None] | None,
             simulation: float | None, users: int, batches: Sequence[tuple[float, float]],
             level: float, *, proportion: bool = False,
             ordinary_no_spread: Mapping[str, Any] | None = None,
             draw_users: int = 0) -> dict[str, Any]:
    """The widened interval of one metric (see the module docstring). Each interval of no
    width because the users were all alike has its ``…_no_spread`` beside it
    (:mod:`opspec.statistics.no_spread`): the ordinary one's is ``ordinary_no_spread`` (the
    summary's own), the widened one's over the same users of the ordinary run (it has no
    width only when they were all alike; ``users`` when the summary's is not given), the
    direct bootstrap's over the ``draw_users`` of the batches (those with a value) when
    every one of them gave the same value too."""
    from opspec.statistics import t_quantile

    out: dict[str, Any] = {"estimate": estimate, "ci95": list(ordinary) if ordinary else None,
                           "ci95_no_spread": ordinary_no_spread, "draws": len(batches)}
    if estimate is None or simulation is None or len(batches) < 2:
        return {**out, "ci95_with_parameters": None,
                "ci95_with_parameters_no_spread": None, "direct_bootstrap_ci95": None,
                "direct_bootstrap_ci95_no_spread": None,
                "variance": None, "parameter_share": None}
    values = [v for v, _ in batches]
    between = pystats.variance(values)
    noise = pystats.fmean(s for _, s in batches)
    parameters = max(between - noise, 0.0)
    total = simulation + parameters
    b = len(batches)
    if total > 0:
        denominator = ((simulation ** 2 / (users - 1) if users > 1 else 0.0)
                       + parameters ** 2 / (b - 1))
        df = total ** 2 / denominator if denominator > 0 else float(users - 1)
        half = t_quantile(level, max(1, math.floor(df))) * math.sqrt(total)
    else:
        df, half = float(users - 1), 0.0
    low, high = estimate - half, estimate + half
    if ordinary and ordinary[0] is not None and ordinary[1] is not None:
        if ordinary[0] >= 0 and low < 0 and estimate >= 0:
            low = 0.0           # as the ordinary interval: a rate cannot be negative
        low, high = min(low, ordinary[0]), max(high, ordinary[1])
    if proportion:      # never below the ordinary interval it widens
        high = min(high, max(1.0, ordinary[1] if ordinary and ordinary[1] is not None
                             else 1.0))
    ordered = sorted(values)
    alpha = (1 - level) / 2
    bootstrap = [linear(ordered, alpha), linear(ordered, 1 - alpha)]
    # the batches' estimates all alike is no spread seen only when their users were too
    # (equal batch means of users who differ are no such thing); a variance of users all
    # alike can come out a few units in the last place above 0
    tiny = (1e-12 * max(abs(v) for v in values)) ** 2
    alike = between <= tiny and noise <= tiny
    return {**out, "ci95_with_parameters": [low, high],
            "ci95_with_parameters_no_spread": no_spread(
                [low, high], (ordinary_no_spread or {}).get("users", users), level),
            "direct_bootstrap_ci95": bootstrap,
            "direct_bootstrap_ci95_no_spread": (no_spread(bootstrap, draw_users, level)
                                                if alike else None),
            "variance": {"parameters": parameters, "simulation": simulation,
                         "between_draws": between, "within_draws": noise},
            "parameter_share": parameters / total if total > 0 else 0.0,
            "df": df}


def _proportion(definition: Mapping[str, Any]) -> bool:
    """Whether the metric is a proportion (bounded by 1): a ratio the spec declares one
    (``Proportion="true"``). The declaration, never the numbers of this run, says it, as for
    the ordinary summary (:mod:`opspec.evaluation.design_summary`): a count whose users each
    had 0 or 1 events looks like one, and its interval must not be cut at 1."""
    return definition.get("kind") == "ratio" and definition.get("proportion") is True


def _batches(store: Any, plan: Any, label: str, definition: Mapping[str, Any]
             ) -> dict[int, dict[int, tuple[float, float]]]:
    """Per draw, per user of its batch: the metric's (y, n) pair."""
    from opspec.evaluation.summary import user_pairs

    out: dict[int, dict[int, tuple[float, float]]] = {}
    for user, pair in user_pairs(store, draws_label(label), definition):
        out.setdefault(draw_of(plan.users, plan.users_per_draw, user), {})[user] = pair
    return out


def summarise_input_uncertainty(store: Any, plan: Any, metrics: Mapping[str, Any],
                                level: float = 0.95, *, design: str = "A",
                                compare: Mapping[str, Any] | None = None
                                ) -> dict[str, Any] | None:
    """Per metric of ``design`` (``metrics``: its ordinary summary): the ordinary ``ci95``,
    ``ci95_with_parameters``, ``direct_bootstrap_ci95``, the ``variance`` split and the
    ``parameter_share``; with ``compare`` (the ordinary paired differences) the same for
    each difference B − A. None for a run without parameter draws."""
    if not plan.input_uncertainty:
        return None
    from opspec.evaluation.summary import metric_definitions, user_pairs

    out: dict[str, Any] = {"draws": plan.input_uncertainty,
                           "users_per_draw": plan.users_per_draw,
                           "method": "direct bootstrap (Barton & Schruben 2001) with the "
                           "random-effects variance split of Ankenman & Nelson (2012)",
                           "metrics": {}}
    for definition in metric_definitions(store, design):
        name = definition["name"]
        ordinary = metrics.get(name) or {}
        pairs = [p for _, p in user_pairs(store, design, definition)]
        plain = ratio_variance(pairs)
        # a user without a denominator (no dose, for a rate per dose) gives no value
        drawn = [(sum(1 for _, n in users.values() if n > 0), e)
                 for users in _batches(store, plan, design, definition).values()
                 if (e := ratio_variance(list(users.values()))) is not None]
        estimate = ordinary.get("value", ordinary.get("mean"))
        out["metrics"][name] = _combine(estimate, ordinary.get("ci95"),
                                        plain[1] if plain else None, len(pairs),
                                        [e for _, e in drawn], level,
                                        proportion=_proportion(definition),
                                        ordinary_no_spread=ordinary.get("ci95_no_spread"),
                                        draw_users=sum(n for n, _ in drawn))
    if compare:
        out["difference"] = {}
        theirs = {d["name"]: d for d in metric_definitions(store, "B")}
        for definition in metric_definitions(store, design):
            name = definition["name"]
            if name not in compare or name not in theirs:
                continue
            a = dict(user_pairs(store, design, definition))
            b = dict(user_pairs(store, "B", theirs[name]))
            common = sorted(set(a) & set(b))
            plain = paired_variance([a[u] for u in common], [b[u] for u in common])
            batch_a = _batches(store, plan, design, definition)
            batch_b = _batches(store, plan, "B", theirs[name])
            batches, drawn = [], 0
            for draw, users_a in batch_a.items():
                users_b = batch_b.get(draw, {})
                both = sorted(set(users_a) & set(users_b))
                found = paired_variance([users_a[u] for u in both], [users_b[u] for u in both])
                if found is not None:
                    batches.append(found)
                    drawn += sum(1 for u in both if users_a[u][1] > 0 or users_b[u][1] > 0)
            entry = compare[name]
            out["difference"][name] = _combine(entry.get("difference"), entry.get("ci95"),
                                               plain[1] if plain else None, len(common),
                                               batches, level,
                                               ordinary_no_spread=entry.get("ci95_no_spread"),
                                               draw_users=drawn)
    return out


# ------------------------------------------------------------------------------ printing

def _number(value: float | None) -> str:
    return "-" if value is None else f"{value:.4g}"


def _interval(ci: Sequence[float | None] | None, show: Any = _number) -> str:
    if not ci or ci[0] is None or ci[1] is None:
        return "-"
    return f"[{show(ci[0])}, {show(ci[1])}]"


HEADERS = ("metric", "estimate", "95 % CI (simulation)", "95 % CI (+ parameters)",
           "direct bootstrap", "from parameters")


#: The intervals of a row, each with the key of its ``…_no_spread`` (:func:`_combine`).
_INTERVALS = (("ci95", "ci95_no_spread"),
              ("ci95_with_parameters", "ci95_with_parameters_no_spread"),
              ("direct_bootstrap_ci95", "direct_bootstrap_ci95_no_spread"))


def _alike(entry: Mapping[str, Any], key: str, difference: bool) -> dict[str, Any]:
    """One interval of ``entry`` as :mod:`.no_spread_notes` reads a summary."""
    return {"ci95_no_spread": entry.get(key), **({"difference": True} if difference else {})}


def _in_units(declared: Mapping[str, Any] | None, difference: bool) -> Any:
    """How a number of the metric ``declared`` (its summary, or its difference's) is written,
    as the run's own tables write it: a proportion in %, its difference in pp, a duration
    with its unit; without ``declared``, a plain number."""
    from opspec.evaluation.tables import difference_text, fmt, in_percent

    if declared is None:
        return _number
    percent = in_percent(declared)
    unit = "" if percent else (declared.get("unit") or "")
    if difference:
        return lambda value: difference_text(value, unit, percent=percent)
    return lambda value: fmt(value, unit, percent=percent)


def _rows(summary: Mapping[str, Any], metrics: Mapping[str, Any] | None = None,
          difference: Mapping[str, Any] | None = None) -> list[tuple[str, ...]]:
    """The table's rows; with the run's ``metrics`` (and the ``difference`` of a
    comparison), in each metric's units: 98.83 %, not 0.9883, beside the run's table."""
    rows: list[tuple[str, ...]] = []
    for section, prefix, declared in (("metrics", "", metrics),
                                      ("difference", "B - A: ", difference)):
        for name, entry in (summary.get(section) or {}).items():
            share = entry.get("parameter_share")
            show = _in_units(None if declared is None else declared.get(name),
                             section == "difference")
            rows.append((prefix + name, show(entry.get("estimate")),
                         *(with_mark(_interval(entry.get(ci), show),
                                     _alike(entry, alike, False))
                           for ci, alike in _INTERVALS),
                         "-" if share is None else f"{100 * share:.0f} %"))
    return rows


def _note(summary: Mapping[str, Any]) -> str | None:
    """What a marked interval of the table means, once (:mod:`.no_spread_notes`)."""
    return no_spread_note(_alike(entry, alike, section == "difference")
                          for section in ("metrics", "difference")
                          for entry in (summary.get(section) or {}).values()
                          for _, alike in _INTERVALS)


def _title(summary: Mapping[str, Any]) -> str:
    return (f"{summary['draws']} parameter draws of the fitted model x "
            f"{summary['users_per_draw']} users each ({summary['method']})")


def report_section(store: Any, given: Mapping[str, Any],
                   difference: Mapping[str, Any] | None) -> Any:
    """The report's section on input uncertainty (``given``: design A's summaries)."""
    from opspec.evaluation.html import Section, Table
    from opspec.evaluation.plan import EvaluationPlan

    summary = given.get("input_uncertainty")
    if summary is None:
        from opspec.evaluation.summary import compare_designs, summarise_design

        plan = EvaluationPlan.from_json(store.get("plan"))
        metrics = given.get("metrics") or summarise_design(store, "A", plan.days)
        if difference is None and any(d.label == "B" for d in plan.designs):
            difference = compare_designs(store)
        summary = summarise_input_uncertainty(store, plan, metrics, compare=difference)
    assert summary is not None
    return Section("With the fitted model's parameter uncertainty", paragraphs=(
        ("The user model was fitted from recorded traces, so its parameters are estimates. "
        f"{_title(summary)}: each draw is the model refitted to a bootstrap resample of "
        "the traces, run on users of its own. 'from parameters' is the share of the "
        "widened interval's variance due to the parameters; more simulated users narrow "
        "only the rest, more recorded observations narrow this part. The widened "
        "interval adds the between-draw variance of the estimates, less their "
        "within-draw (simulation) variance, to the ordinary variance, on Satterthwaite's "
        "degrees of freedom, and covers the ordinary interval."),
        *filter(None, [_note(summary)])),
        tables=(Table(HEADERS, tuple(_rows(summary, given.get("metrics"), difference)),
                      "Ordinary 95 % intervals (simulation noise only) and intervals that "
                      "include the fitted parameters' uncertainty"),))


def print_input_uncertainty(out: IO[str], summary: Mapping[str, Any] | None,
                            metrics: Mapping[str, Any] | None = None,
                            difference: Mapping[str, Any] | None = None) -> None:
    """The table of ordinary and widened intervals, after the ordinary summary (``metrics``,
    ``difference``: the run's summaries, whose units the table's numbers are written in)."""
    if not summary:
        return
    rows = [HEADERS, *_rows(summary, metrics, difference)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    print(f"\nInput uncertainty: {_title(summary)}", file=out)
    for row in rows:
        print("  " + "  ".join(c.ljust(w) if i == 0 else c.rjust(w)
                               for i, (c, w) in enumerate(zip(row, widths, strict=True))),
              file=out)
    print("  'from parameters': the share of the widened interval's variance due to the "
          "fitted parameters;\n  more users narrow only the rest.", file=out)
    if note := _note(summary):
        print(f"\n{note}", file=out)
