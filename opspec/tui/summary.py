"""The end of a walkthrough in words: the spec's metrics, the person's response times, where
the recording is.

The metrics are those ``opspec run`` prints for the same run (the spec's ``opspec:Metrics``:
doses taken and missed, alarms, report latency...), formatted the same way, so the numbers a
coordinator reads at the end of a session are those ``opspec run SPEC --script RECORDING``
prints. The response times are the person's own, in wall-clock seconds from the offer reaching
them to their key (:mod:`opspec.tui.timing`), with how many of them are usable for
``opspec fit``.
"""

from __future__ import annotations

import shlex
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from statistics import median

from opspec.clock import try_duration
from opspec.evaluation.run_metrics_text import metric_lines
from opspec.tui.timing import Response

__all__ = ["metric_lines", "replay_commands", "response_lines", "until_text"]


def response_lines(responses: Sequence[Response], *, recorded: bool = True) -> list[str]:
    """The person's response times per action (wall clock), and how many are usable for
    ``opspec fit`` (with the reasons the others are not); not ``recorded`` (``--no-record``),
    none is: there is no trace to fit. What the person chose not to do (``x``) has no
    response time: it is counted apart, by action."""
    skipped = Counter(r.label for r in responses if r.omitted)
    # (opspec fit counts them as omissions, timed or not: they are not its durations either)
    said = ["  not done (x, no response time): "
            + "; ".join(f"{label} ({n})" for label, n in skipped.items())] if skipped else []
    responses = [r for r in responses if not r.omitted]
    if not responses:
        return ["  (you answered nothing)", *said]
    per: dict[str, list[float]] = {}
    for response in responses:
        if response.wall_s is not None:
            per.setdefault(response.label, []).append(response.wall_s)
    width = max((len(label) for label in per), default=0)
    lines = [f"  {label:<{width}}  median {median(times):.1f} s, max {max(times):.1f} s, "
             f"n {len(times)}" for label, times in per.items()]
    lines += said
    if not recorded:
        lines.append("  (nothing was recorded: opspec fit has no trace of them)")
        return lines
    usable = sum(1 for r in responses if r.usable)
    why = Counter(r.why for r in responses if not r.usable and r.why)
    # the count after its reason: "2x the clock ran at 60x" read as a speed
    lines.append(f"  usable for opspec fit: {usable} of {len(responses)}"
                 + (" (not usable: " + "; ".join(f"{reason} ({n})"
                                                for reason, n in why.most_common())
                    + ")" if why else " (the clock ran in real time)"))
    return lines


def replay_commands(spec: str | Path, record: str | Path, *, until: float | None = None,
                    seed: int = 0) -> tuple[str, str]:
    """The two commands that replay ``record`` (quoted for a POSIX shell, so a path with
    spaces pastes as it is): in the walkthrough, and with ``opspec run``. ``until``: the
    simulated second the session ended at (or stands at, in a summary so far), when that is
    not where the spec's run ends by itself (the person quit before the end, or ``--days``
    set another end): both replays stop there too (``--until``), so that they print the
    numbers the summary shows, not those of a run that goes on without the person. ``seed``: the session's run seed (``--seed``, left
    out when 0): the device's draws of another seed would be another session."""
    spec_q, record_q = shlex.quote(str(spec)), shlex.quote(str(record))
    same = "" if not seed else f" --seed {seed}"
    if until is not None:
        same += f" --until {until_text(until)}"
    return (f"opspec walkthrough {spec_q} --replay {record_q}{same}",
            f"opspec run {spec_q}{same} --script {record_q}")


def until_text(until: float) -> str:
    """``until`` as ``--until`` reads it back to the same float: in days, hours, minutes and
    seconds (``18h16m4.89972954505s``, the walkthrough's clock at a glance) when that text
    reads back exactly, else the shortest number that does (``repr``). Never rounded: a run
    stopped a fraction of a second earlier or later could leave out, or take in, an event the
    session did not have."""
    exact = repr(float(until))
    whole, dot, fraction = exact.partition(".")
    if not dot or not whole.isdigit() or not fraction.isdigit() or int(whole) < 60:
        return exact                   # under a minute, or 1e+20: nothing clearer to say
    days, rest = divmod(int(whole), 86_400)
    hours, rest = divmod(rest, 3_600)
    minutes, seconds = divmod(rest, 60)
    fraction = fraction.rstrip("0")
    second = f"{seconds}.{fraction}" if fraction else (str(seconds) if seconds else "")
    text = "".join(f"{count}{unit}" for count, unit in (
        (days, "d"), (hours, "h"), (minutes, "m"), (second, "s")) if count)
    # the digits are repr's, split at whole minutes; the sum is checked, not trusted
    return text if try_duration(text) == until else exact
