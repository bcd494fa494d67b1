"""The summary of a walkthrough study (``opspec study PROTOCOL.toml`` without
``--participant``): each metric of each variant over the participants who finished it, and
the paired difference of each pair of variants over the participants who did both, replayed
from the sessions' traces (:mod:`opspec.tui.study` runs the sessions). An interval of no width
from too few participants who were all alike is marked and explained as ``opspec evaluate``
does (:mod:`opspec.statistics.no_spread`, :mod:`opspec.evaluation.no_spread_notes`): it shows
no spread between them, not a value known exactly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from opspec.errors import ConfigurationError, SourceLocation

if TYPE_CHECKING:
    from opspec.model import MetricDefinition
    from opspec.tui.study import Protocol, Session, Variant

__all__ = ["session_pairs", "summary", "summary_lines", "variant_estimate"]


def _pairs(listener: Any) -> dict[str, tuple[float, float]]:
    """Per metric of one session, the (numerator, denominator) pair ``opspec evaluate
    --compare`` pairs by user: a count (total, 1), a duration (sum, n), a ratio (its
    numerator's value, its denominator's)."""
    from opspec.model import MetricKind

    values = listener.values()
    out: dict[str, tuple[float, float]] = {}

    def scalar(name: str | None) -> float | None:
        v = values.get(name or "")
        if v is None:
            return None
        result = (v.get("total") if v["kind"] == "count" else v.get("mean")
                  if v["kind"] == "duration" else v.get("value"))
        return None if result is None else float(result)

    for metric in listener.definitions:
        if metric.kind is MetricKind.COUNT:
            out[metric.name] = (float(values[metric.name]["total"]), 1.0)
        elif metric.kind is MetricKind.DURATION:
            samples = listener.samples.get(metric.name, [])
            if samples:
                out[metric.name] = (float(sum(samples)), float(len(samples)))
        elif metric.kind is MetricKind.RATIO:
            num, den = scalar(metric.numerator), scalar(metric.denominator)
            if num is not None and den:
                out[metric.name] = (num, den)
    return out


def session_pairs(session: Session) -> dict[str, tuple[float, float]]:
    """The metric pairs of a done session, replayed from its trace."""
    from opspec.engine.metrics import MetricsListener
    from opspec.engine.trace_sinks import read_trace
    from opspec.xpdl.open_spec import open_spec

    trace = session.trace
    try:
        with trace.open("rb") as handle:
            last = b"\n"
            if handle.seek(0, 2) > 0:
                handle.seek(-1, 2)
                last = handle.read(1)
        cut = last != b"\n"
    except OSError as error:
        raise ConfigurationError(
            f"the trace of a session marked done cannot be read ({error.strerror or error})",
            location=SourceLocation(str(trace)),
            hint=f"put it back, or delete {session.done_marker.name} to run the session "
            "again") from None
    if cut:
        # a reader of a crashed run's trace skips a cut last line; a session marked done
        # ended whole, so its trace was cut afterwards and its metrics would be short
        raise ConfigurationError(
            "the trace of a session marked done ends in a cut line: it is not the whole "
            "session", location=SourceLocation(str(trace)),
            hint=f"restore it from a copy, or delete {session.done_marker.name} to run the "
            "session again")
    listener = MetricsListener(open_spec(session.variant.spec).metrics)
    for event in read_trace(trace):
        listener(event)
    return _pairs(listener)


def _metric_definitions(variant: Variant) -> dict[str, MetricDefinition]:
    """Each metric of ``variant``'s spec, by name."""
    from opspec.xpdl.open_spec import open_spec

    return {m.name: m for m in open_spec(variant.spec).metrics}


def variant_estimate(kind: str | None, pairs: list[tuple[float, float]],
                     definition: MetricDefinition | None = None,
                     of_counts: bool = False) -> dict[str, Any]:
    """One metric of one variant over its participants, as ``opspec evaluate`` summarises a
    design: a count's mean per participant with the t interval widened to the exact Poisson
    (Garwood) one when there are few events, a ratio by its ``definition``
    (:func:`opspec.statistics.ratios.ratio_interval`: one the spec declares a proportion,
    missed / due doses, with Wilson's interval on the effective number of trials; another
    with the cluster-robust t interval, widened to the exact Poisson one for a ratio of
    counts, ``of_counts``, with few events), anything else Σy/Σn with the cluster-robust t
    interval. A t interval alone says [0, 0] for a count nobody had and a rate of 0 of 16
    doses, as if they could not happen."""
    from opspec.statistics import count_estimate, ratio_estimate
    from opspec.statistics.no_spread import no_spread
    from opspec.statistics.ratios import ratio_interval

    estimate = ratio_estimate(pairs)
    ci, method = estimate.ci, estimate.method
    if kind == "count":
        estimate = count_estimate([y for y, _ in pairs])
        ci, method = estimate.ci, estimate.method
    elif kind == "ratio" and definition is not None:
        interval = ratio_interval(pairs, proportion=definition.proportion, of_counts=of_counts,
                                  name=definition.name, numerator=str(definition.numerator),
                                  denominator=str(definition.denominator))
        ci, method = interval.ci, interval.method
    return {"value": estimate.value, "ci95": list(ci), "ci95_method": method,
            # [v, v] because every participant gave v: said as opspec evaluate says it
            "ci95_no_spread": no_spread(ci, len(pairs)),
            "unit": "s" if kind == "duration" else None, "participants": len(pairs),
            # the spec's declaration: a proportion is shown in percent, as opspec run and
            # opspec evaluate show it (never from its name or numbers)
            "proportion": bool(kind == "ratio" and definition is not None
                               and definition.proportion)}


def summary(protocol: Protocol) -> dict[str, Any]:
    """Per variant, each metric over the participants who finished it
    (:func:`variant_estimate`); per pair of variants, the paired difference over the
    participants who finished both (``opspec evaluate --compare``'s statistics: a ratio
    over users with its delta-method interval)."""
    from opspec.statistics import paired_difference, ratio_estimate
    from opspec.statistics.no_spread import no_spread

    done: dict[str, dict[str, dict[str, tuple[float, float]]]] = {}
    status: dict[str, dict[str, bool]] = {}
    for participant in protocol.participants:
        status[participant] = {}
        for s in protocol.sessions(participant):
            status[participant][s.variant.id] = s.done
            if s.done:
                done.setdefault(s.variant.id, {})[participant] = session_pairs(s)
    variants: dict[str, Any] = {}
    kinds: dict[str, str] = {}
    for v in protocol.variants:
        people = done.get(v.id, {})
        metrics: dict[str, Any] = {}
        names = sorted({m for pairs in people.values() for m in pairs})
        of_variant = _metric_definitions(v) if names else {}
        counted = {n for n, m in of_variant.items() if m.kind.value == "count"}
        for name in names:
            declared = of_variant.get(name)
            kind = declared.kind.value if declared is not None else None
            kinds.setdefault(name, kind or "")
            pairs = [p[name] for p in people.values() if name in p]
            metrics[name] = variant_estimate(
                kind, pairs, declared, of_counts=declared is not None
                and {declared.numerator, declared.denominator} <= counted)
        variants[v.id] = {"participants": len(people), "metrics": metrics}
    comparisons = []
    ids = [v.id for v in protocol.variants]
    for i, a in enumerate(ids):
        for b in ids[i + 1:]:
            both = sorted(set(done.get(a, {})) & set(done.get(b, {})))
            rows: dict[str, Any] = {}
            names = sorted({m for p in both for m in done[a][p]} &
                           {m for p in both for m in done[b][p]})
            for name in names:
                who = [p for p in both if name in done[a][p] and name in done[b][p]]
                if len(who) < 2:
                    continue
                diff = paired_difference([done[a][p][name] for p in who],
                                         [done[b][p][name] for p in who])
                rows[name] = {"a": ratio_estimate([done[a][p][name] for p in who]).value,
                              "b": ratio_estimate([done[b][p][name] for p in who]).value,
                              "difference": diff.value, "ci95": list(diff.ci),
                              "ci95_method": diff.method,
                              "ci95_no_spread": no_spread(diff.ci, len(who)),
                              "unit": "s" if kinds.get(name) == "duration" else None,
                              "participants": len(who),
                              "proportion": any(variants[v]["metrics"].get(name, {}).get(
                                  "proportion") for v in (a, b))}
            comparisons.append({"a": a, "b": b, "participants": both, "metrics": rows})
    return {"study": protocol.name, "status": status, "variants": variants,
            "comparisons": comparisons}


def summary_lines(doc: dict[str, Any]) -> list[str]:
    """The summary as the terminal shows it: a declared proportion in percent (a difference
    of two in percentage points), a difference signed, as opspec evaluate's tables write
    them (:mod:`opspec.evaluation.tables`); an interval of no width from too few participants
    all alike marked ``†``, with one note at the end saying what the mark means, in the words
    of opspec evaluate's (:mod:`opspec.evaluation.no_spread_notes`)."""
    from opspec.evaluation.no_spread_notes import no_spread_note, with_mark
    from opspec.evaluation.tables import difference_text

    def num(x: Any, unit: str | None = None, *, percent: bool = False,
            difference: bool = False) -> str:
        if x is None:
            return "-"
        if difference:
            return difference_text(x, unit or "", percent=percent)
        if percent:
            return f"{x * 100:.2f} %"
        return f"{x:.4g}" + (f" {unit}" if unit else "")

    def interval(m: dict[str, Any], none: str, *, difference: bool = False) -> str:
        lo, hi = m["ci95"]
        unit, percent = m.get("unit"), bool(m.get("proportion"))
        if lo is None or hi is None:        # "[-, -]" said nothing of why
            return f"no 95 % CI: {none}; n = {m['participants']}"
        shown = [num(x, percent=percent, difference=difference) for x in (lo, hi)]
        ci = with_mark(f"[{shown[0]}, {shown[1]}]{' ' + unit if unit else ''}", m)
        return f"95 % CI {ci}; n = {m['participants']}"

    lines = [f"study {doc['study']}"]
    for participant, sessions in doc["status"].items():
        lines.append(f"  {participant}: " + ", ".join(
            f"{v} {'done' if ok else 'to do'}" for v, ok in sessions.items()))
    for vid, v in doc["variants"].items():
        lines.append(f"variant {vid} ({v['participants']} participant(s) finished):")
        for name, m in v["metrics"].items():
            lines.append(f"  {name}: "
                         f"{num(m['value'], m.get('unit'), percent=bool(m.get('proportion')))}"
                         f" ({interval(m, 'one participant')})")
    for c in doc["comparisons"]:
        lines.append(f"{c['b']} - {c['a']}, paired over {len(c['participants'])} "
                     "participant(s) who did both:")
        if not c["metrics"]:
            lines.append("  (needs two participants or more who did both)")
        for name, m in c["metrics"].items():
            unit, percent = m.get("unit"), bool(m.get("proportion"))
            lines.append(f"  {name}: {num(m['a'], unit, percent=percent)} -> "
                         f"{num(m['b'], unit, percent=percent)}, difference "
                         f"{num(m['difference'], unit, percent=percent, difference=True)} ("
                         + interval(m, "fewer than two participants differ between the "
                                    "variants", difference=True) + ")")
    # what a marked interval means, once for every line above (as under evaluate's tables)
    note = no_spread_note([*(m for v in doc["variants"].values()
                             for m in v["metrics"].values()),
                           *(m for c in doc["comparisons"] for m in c["metrics"].values())])
    if note:
        lines += ["", note]
    return lines

