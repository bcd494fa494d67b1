"""How the tables, the report and its figures show an interval of no width from too few users
who were all alike (:mod:`opspec.statistics.no_spread`): a mark after the interval, and one
note, in plain words, under the table or figure that has it (docs/evaluation.md, *Intervals
of no width*)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

__all__ = ["MARK", "figure_marks", "marked", "no_spread_note", "with_mark"]

#: After an interval of no width from too few users: ``[4, 4] †``.
MARK = "†"


def marked(summary: Mapping[str, Any] | None) -> bool:
    """Whether ``summary``'s ``ci95`` has no width because its few users were all alike."""
    return bool(((summary or {}).get("ci95_no_spread") or {}).get("too_few_users"))


def with_mark(ci: str, summary: Mapping[str, Any] | None) -> str:
    """An interval's cell, marked when :func:`marked`."""
    return f"{ci} {MARK}" if marked(summary) and ci != "–" else ci


def _users(counts: list[int]) -> str:
    distinct = sorted(set(counts))
    if len(distinct) == 1:
        return f"all {distinct[0]:,} users"
    return ("all the users of each marked interval (" + ", ".join(f"{n:,}" for n in
                                                                distinct[:-1])
            + f" or {distinct[-1]:,})")


def no_spread_note(summaries: Iterable[Mapping[str, Any] | None]) -> str | None:
    """The note under a table whose rows are ``summaries`` (metrics or differences), when one
    of their intervals is marked: what the mark means, once; None when none is."""
    shown = [s for s in summaries if marked(s)]
    if not shown:
        return None
    spreads = [s["ci95_no_spread"] for s in shown]
    counts = [int(n["users"]) for n in spreads]
    fewest = min(spreads, key=lambda n: n["users"])
    same = ("the same value" if not any("difference" in s for s in shown)
            else "the same difference between the designs" if all("difference" in s
                                                                    for s in shown)
            else "the same value (or the same difference between the designs)")
    return (f"{MARK} {_users(counts)} gave {same}, so the interval has no width: it shows no "
            "spread between users, not a value known exactly. Unless the spec fixes the value (a "
            "count of events on a fixed schedule), more users are needed to estimate its "
            "interval: "
            f"with {fewest['users']:,} users all alike"
            f"{' (the fewest)' if len(set(counts)) > 1 else ''}, up to "
            f"{100 * fewest['share_unlike_ci95_high']:.3g} % of users could give another value "
            "(exact 95 % bound).")


def figure_marks(summaries: Mapping[str, Iterable[Mapping[str, Any] | None]]
                 ) -> dict[str, Any]:
    """What a figure function is given to mark its intervals (``no_spread``: the panels or
    rows, by name, with one interval of no width from too few users, ``no_spread_note``:
    :func:`no_spread_note` of them all), from each name's summaries (one per interval it
    draws); nothing when none is marked, so the figure is asked for as before."""
    every = {name: list(shown) for name, shown in summaries.items()}
    alike = [name for name, shown in every.items() if any(map(marked, shown))]
    if not alike:
        return {}
    return {"no_spread": alike,
            "no_spread_note": no_spread_note(s for shown in every.values() for s in shown)}
