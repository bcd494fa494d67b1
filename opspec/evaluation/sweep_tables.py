"""The tables of a sweep (``opspec evaluate --sweep``), as the terminal and the report show
them: per metric, each value's estimate and interval and the paired difference against the
first value, each interval with the method that computed it (the "CI method" columns, as
every other table of an evaluation names its intervals' methods), and the targets' answers;
:func:`print_sweep` prints them with what their marks and methods mean.
(:mod:`opspec.evaluation.sweep` summarises the sweep and draws its figure.)"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import IO, Any

from opspec.evaluation.no_spread_notes import MARK, marked, no_spread_note, with_mark

__all__ = ["SWEEP_HEADERS", "metric_table", "print_sweep", "target_table"]


def _estimate(summary: Mapping[str, Any]) -> tuple[float | None, list[float | None]]:
    value = summary.get("value", summary.get("mean"))
    return value, list(summary.get("ci95") or [None, None])



def _cells(name: str, summary: Mapping[str, Any] | None) -> tuple[str, str]:
    from opspec.evaluation.tables import fmt, in_percent

    if summary is None:
        return "–", "–"
    percent = in_percent(summary)
    unit = "" if percent or summary["kind"] != "duration" else (summary.get("unit") or "s")
    estimate, (low, high) = _estimate(summary)
    ci = ("–" if low is None or high is None
          else with_mark(f"[{fmt(low, unit, percent=percent)}, "
                         f"{fmt(high, unit, percent=percent)}]", summary))
    return fmt(estimate, unit, percent=percent), ci


def _difference_cells(name: str, d: Mapping[str, Any] | None) -> tuple[str, str, str]:
    from opspec.evaluation.tables import in_percent

    if d is None:
        return "(reference)", "", ""
    percent = in_percent(d)
    unit = "" if percent else (d.get("unit") or "")

    def show(x: Any) -> str:
        if x is None:
            return "–"
        return f"{x * 100:+.3g} pp" if percent else f"{x:+.4g}" + (f" {unit}" if unit else "")

    low, high = d.get("ci95") or [None, None]
    ci = "–" if low is None or high is None else with_mark(f"[{show(low)}, {show(high)}]", d)
    paired = _width(d.get("ci95"))
    unpaired = _width(d.get("unpaired_ci95"))
    ratio = (f"{paired / unpaired:.2f}" if paired is not None and unpaired
             else "–")
    if marked(_unpaired(d)):        # no ratio, as the unpaired interval has no width
        ratio += f" {MARK}"
    return show(d["difference"]) + (" *" if d.get("significant") else ""), ci, ratio


def _unpaired(d: Mapping[str, Any]) -> dict[str, Any]:
    """A difference's unpaired interval as :mod:`.no_spread_notes` reads a summary: of
    each value's users apart (all alike in both, when it has no width)."""
    return {"ci95_no_spread": d.get("unpaired_ci95_no_spread")}


def _note(summary: Mapping[str, Any]) -> str | None:
    """What a marked interval of the sweep's tables means, once (:mod:`.no_spread_notes`)."""
    differences = [d for v in summary["values"] for d in (v["difference"] or {}).values()]
    return no_spread_note([*(s for v in summary["values"] for s in v["metrics"].values()),
                           *differences, *map(_unpaired, differences)])


def _width(ci: Sequence[float | None] | None) -> float | None:
    if not ci or ci[0] is None or ci[1] is None:
        return None
    return float(ci[1]) - float(ci[0])


SWEEP_HEADERS = ("value", "estimate", "95 % CI", "CI method", "difference",
                 "95 % CI (paired)", "CI method (paired)", "paired/unpaired width")


def metric_table(summary: Mapping[str, Any], metric: str) -> list[tuple[str, ...]]:
    """One row per value: the metric's estimate and interval, the paired difference against
    the first value with its interval, and how much narrower the paired interval is than an
    unpaired one (the gain of common random numbers)."""
    rows: list[tuple[str, ...]] = []
    from opspec.evaluation.tables import method_name

    for entry in summary["values"]:
        s = entry["metrics"].get(metric)
        d = (entry["difference"] or {}).get(metric) if entry["difference"] else None
        difference, ci, ratio = _difference_cells(metric, d if entry["difference"] else None)
        rows.append((entry["text"], *_cells(metric, s), method_name(s or {}), difference, ci,
                     "" if d is None else method_name(d), ratio))
    return rows


def target_table(answer: Mapping[str, Any], summary: Mapping[str, Any]
                 ) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    """Per value: the estimate and its verdict; with a share of users, the share of users
    meeting the target with its exact interval and that verdict. ``summary``: the sweep's
    (:func:`summarise_sweep`), whose metric summaries carry the spec's declaration, which
    says whether the estimates are in percent."""
    from opspec.evaluation.tables import fmt, in_percent

    percent = any(in_percent(v["metrics"].get(answer["metric"]) or {})
                  for v in summary["values"])
    headers: tuple[str, ...] = ("value", "estimate", "95 % CI", "mean")
    share = answer.get("users_share")
    if share is not None:
        headers += ("users meeting", "95 % CI (exact)", f"{100 * share:.4g} % of users")
    rows = []
    for row in answer["values"]:
        low, high = row["ci95"]
        cells: tuple[str, ...] = (
            row["text"], fmt(row["estimate"], percent=percent),
            "–" if low is None or high is None
            else with_mark(f"[{fmt(low, percent=percent)}, {fmt(high, percent=percent)}]",
                           row),
            row["verdict"])
        if share is not None:
            users = row["users"]
            ci = users["share_ci95"]
            cells += (fmt(users["share"], percent=True),
                      "–" if not ci else f"[{fmt(ci[0], percent=True)}, "
                      f"{fmt(ci[1], percent=True)}]", users["verdict"])
        rows.append(cells)
    return headers, rows


def print_sweep(out: IO[str], summary: Mapping[str, Any], users: int) -> None:
    """The sweep as the terminal shows it: a table per metric, then the targets' answers."""
    from opspec.evaluation.tables import table

    print(f"sweep of {summary['parameter']} ({summary['what']}): {len(summary['values'])} "
          f"values on the same {users} simulated users (common random numbers); differences "
          f"are paired, each value minus the first ({summary['reference']}); * the 95 % "
          "interval excludes 0", file=out)
    for metric, first in summary["values"][0]["metrics"].items():
        print(f"\n{metric} ({first['kind']})", file=out)
        for line in table(SWEEP_HEADERS, metric_table(summary, metric)):
            print("  " + line, file=out)
    if note := _note(summary):
        print(f"\n{note}", file=out)
    # the methods the tables above name that the run's own table (the first value's) does
    # not, whose legend is printed above them: the paired differences' above all
    from opspec.evaluation.tables import method_legend
    from opspec.statistics.methods import methods_in

    shown = set(methods_in(summary["values"][0]["metrics"], ("ci95_method",)))
    more = [line for line in method_legend(
        [[v["metrics"], v["difference"]] for v in summary["values"]], ("ci95_method",))
        if line.split(":", 1)[0].strip() not in {_name(m) for m in shown}]
    if more:
        print(f"\n95 % intervals of the sweep's tables, besides those above (over the same "
              f"{users} users):", file=out)
        for line in more:
            print(line, file=out)
    for answer in summary["targets"]:
        print(f"\ntarget {answer['target']}:", file=out)
        for line in table(*target_table(answer, summary)):
            print("  " + line, file=out)
        print(f"  {answer['answer']}", file=out)
        if answer.get("users_answer"):
            print(f"  {answer['users_answer']}", file=out)
    if "meets_every_target" in summary:
        every = summary["meets_every_target"]
        print("\nevery target met on average with "
              + (", ".join(every) if every else "no value"), file=out)
    print(file=out)


def _name(method_id: str) -> str:
    from opspec.statistics.methods import METHODS

    return METHODS[method_id].name
