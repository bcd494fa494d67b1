"""Plain-text tables of an evaluation's results (the terminal summary and the report's tables)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import IO, Any

from opspec.engine.monitors import clock
from opspec.evaluation.plan import span

__all__ = ["comparison_rows", "fmt", "is_rate", "metric_rows", "monitor_rows", "per_user_rows",
           "print_summary", "table"]

METRIC_HEADERS = ("metric", "kind", "estimate", "95 % CI", "sd", "median", "p95", "n")
PER_USER_HEADERS = ("metric", "users", "mean", "sd", "95 % CI", "median", "p95")
COMPARE_HEADERS = ("metric", "A", "B", "B − A", "95 % CI", "")
MONITOR_HEADERS = ("monitor", "violations", "users affected", "per user-day", "95 % CI",
                   "first violation")


def fmt(value: Any, unit: str = "", *, percent: bool = False) -> str:
    """A number for people: 4 significant digits, a unit, or a percentage."""
    if value is None:
        return "–"
    if percent:
        return f"{value * 100:.2f} %"
    if isinstance(value, float):
        text = f"{value:.4g}" if abs(value) < 1e6 else f"{value:.3e}"
    else:
        text = str(value)
    return f"{text} {unit}".rstrip()


def is_rate(name: str, summary: Mapping[str, Any]) -> bool:
    """A ratio read as a percentage: named ``…rate``/``…share`` and between 0 and 1."""
    value = summary.get("value", summary.get("a"))
    return (summary["kind"] == "ratio" and name.endswith(("rate", "share"))
            and (value is None or 0.0 <= value <= 1.0))


def _ci(summary: Mapping[str, Any], unit: str = "", *, percent: bool = False) -> str:
    low, high = (summary.get("ci95") or [None, None])
    if low is None or high is None:
        return "–"
    return f"[{fmt(low, unit, percent=percent)}, {fmt(high, unit, percent=percent)}]"


def metric_rows(metrics: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for name, s in metrics.items():
        kind = s["kind"]
        # sd: of the users' totals for a count, of all observations for a duration
        if kind == "count":
            rows.append((name, "count", f"{fmt(s['mean'])} per user", _ci(s), fmt(s["sd"]),
                         fmt(s["median"]), fmt(s["p95"]), f"total {s['total']}"))
        elif kind == "duration":
            unit = s.get("unit") or "s"
            rows.append((name, "duration", fmt(s["mean"], unit), _ci(s, unit),
                         fmt(s["sd"], unit), fmt(s["median"], unit), fmt(s["p95"], unit),
                         str(s["n"])))
        else:
            percent = is_rate(name, s)
            rows.append((name, "ratio", fmt(s["value"], percent=percent),
                         _ci(s, percent=percent), "–", "–", "–", ""))
    return rows


def per_user_rows(metrics: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    """Durations and ratios over users: the spread of each user's own value."""
    rows: list[tuple[str, ...]] = []
    for name, s in metrics.items():
        per_user = s.get("per_user")
        if not per_user or not per_user.get("users"):
            continue
        unit = (s.get("unit") or "s") if s["kind"] == "duration" else ""
        percent = is_rate(name, s)
        rows.append((f"{name} ({'mean per user' if unit else 'per user'})",
                     str(per_user["users"]), fmt(per_user["mean"], unit, percent=percent),
                     fmt(per_user["sd"], unit, percent=percent),
                     _ci(per_user, unit, percent=percent),
                     fmt(per_user["median"], unit, percent=percent),
                     fmt(per_user["p95"], unit, percent=percent)))
    return rows


def monitor_rows(monitors: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    """The spec's monitors: violations, users affected (share), hazard per user-day."""
    rows: list[tuple[str, ...]] = []
    for name, m in monitors.items():
        first = m.get("first")
        where = (f"user {first['user']}, {clock(first['time'])}" if first
                 and first.get("time") is not None else "–")
        share = fmt(m.get("share_affected"), percent=True)
        affected = f"{m['users_affected']} of {m['users']} ({share})"
        rows.append((name, str(m["violations"]), affected, fmt(m["per_user_day"]), _ci(m),
                     where))
    return rows


def _points(value: Any) -> str:
    """A difference of two rates in percentage points: ``-0.54 pp``."""
    return "–" if value is None else f"{value * 100:+.2f} pp"


def comparison_rows(difference: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for name, d in difference.items():
        percent = is_rate(name, d)
        unit = "" if percent else (d.get("unit") or "")
        diff = _points(d["difference"]) if percent else fmt(d["difference"], unit)
        low, high = d.get("ci95") or [None, None]
        ci = (f"[{_points(low)}, {_points(high)}]" if percent and low is not None
              and high is not None else _ci(d, unit))
        rows.append((name, fmt(d["a"], unit, percent=percent),
                     fmt(d["b"], unit, percent=percent), diff, ci,
                     "differs" if d["significant"] else ""))
    return rows


def table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(headers)]
    line = "  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
            for r in rows]
    return out


def print_summary(out: IO[str], plan: Any, metrics: Mapping[str, Any],
                  compare: Mapping[str, Any] | None, outcome: Any,
                  failures: Sequence[tuple[str, int, str]], workers: int,
                  monitors: Mapping[str, Any] | None = None) -> None:
    design = plan.design("A")
    print(f"opspec evaluate: {design.spec}, {plan.users} users x {span(plan.days)}, seed "
          f"{plan.seed}, user model {plan.user_model or 'none'}", file=out)
    ran = f"{outcome.done} replications in {outcome.wall_s:.1f} s on {workers} worker(s)"
    if outcome.skipped:
        ran += f" ({outcome.skipped} already stored)"
    print(ran, file=out)
    print(file=out)
    for line in table(METRIC_HEADERS, metric_rows(metrics)):
        print(line, file=out)
    if monitors:
        print("\nmonitors (opspec:Monitor in the spec; violations per user-day):", file=out)
        for line in table(MONITOR_HEADERS, monitor_rows(monitors)):
            print(line, file=out)
    if compare is not None and compare.get("monitors"):
        print("\nmonitors of B:", file=out)
        for line in table(MONITOR_HEADERS, monitor_rows(compare["monitors"])):
            print(line, file=out)
    if compare is not None:
        print(f"\ncompared with B = {compare['spec']} (same users, paired):", file=out)
        for line in table(COMPARE_HEADERS, comparison_rows(compare["difference"])):
            print(line, file=out)
    if failures:
        print(f"\n{len(failures)} replication(s) failed:", file=out)
        for design_label, user, error in failures[:10]:
            print(f"  {design_label}/{user}: {error}", file=out)
        if len(failures) > 10:
            print(f"  … and {len(failures) - 10} more", file=out)
        print("run again with --resume --out <folder> to complete them", file=out)
    print(file=out)
