"""Do the 95 % intervals of ``opspec evaluate`` cover the truth 95 % of the time? (issue 19)

    python benchmarks/interval_coverage.py [--repetitions 200] [--users 10 20 100]
                                           [--days 30] [--workers 2] [--seed 19000]
                                           [--json FILE]

The truth is the closed form of the reference scenario (``../shared/bench/SCENARIO.md``,
``analytic.py``): missed rate 0.3456 %, 1.1762 alarms per dose, 122.2 s mean report latency.
Each repetition is one evaluation exactly as ``opspec evaluate`` computes it — the same plan,
result store, runner and summaries (``summarise_design``, ``compare_designs``), only without
the report — with its own seed, so repetitions are independent. Design A is
``specs/medication_dispenser.xpdl`` with the reference user (``dispenser-reference``); design
B is the same spec with a fourth alarm (``alarms < 4``), run on the same users (common random
numbers, as ``--compare`` does), whose closed form is the same formula with four 300 s windows;
the paired differences B - A are checked against the difference of the closed forms.

It prints, per number of users and metric, the mean of the repetitions' estimates beside the
truth (a difference there is the simulation's, not the interval's), the share of repetitions
whose interval covered the truth (a repetition without an interval - a paired difference of
durations in fewer than two users - counts as not covered, and is counted under "no CI"), and
the band a correct 95 % interval lands in with probability 0.95 over this many repetitions
(binomial): coverage outside the band is evidence of a wrong interval, inside the band is not
proof of a right one. Repetition r at the i-th user count has seed 19,000 + 1,000 i + r
(``--seed`` moves the 19,000: another set of independent repetitions). Runs
repetitions on ``--workers`` processes (each repetition on one core, one user after another):
about 13 minutes of CPU at the defaults. Which interval a proportion gets was chosen on a
faster model, ``benchmarks/proportion_coverage.py``.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT.parent / "shared" / "bench"
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USER_MODEL = "dispenser-reference"

#: metric of the evaluation -> key of the closed form
METRICS = {"missed_rate": "missed", "alarms_per_dose": "alarms_per_dose",
           "report_latency_s": "lat_mean_s"}


# ---------------------------------------------------------------- the closed form
def _analytic(bench: Path) -> Any:
    """``analytic.py`` of the shared bench folder (it imports its ``scenario.py``)."""
    sys.path.insert(0, str(bench))
    try:
        import analytic  # type: ignore[import-not-found]
    finally:
        sys.path.remove(str(bench))
    return analytic


def closed_form(max_alarms: int = 3, deadline: float = 300.0, bench: Path = BENCH
                ) -> dict[str, float]:
    """``analytic.expectations()`` of ``../shared/bench`` for ``max_alarms`` windows of
    ``deadline`` seconds (the shared file fixes 3 x 300 s): the same derivation, from its own
    walk-time functions. P(missed) = q^M + sum_k p_k P(W > H - a_k); E[alarms] = 1 +
    sum_j P(R > j d); mean latency = E[R | R < H]."""
    analytic = _analytic(bench)
    p_hear = analytic.P_HEAR
    horizon = deadline * max_alarms
    p_first = [p_hear * (1 - p_hear) ** k for k in range(max_alarms)]
    starts = [deadline * k for k in range(max_alarms)]

    def cdf_r(x: float) -> float:
        return sum(p * analytic.cdf_w(x - a) for p, a in zip(p_first, starts) if x > a)

    p_taken = cdf_r(horizon)
    mean = sum(p * (a * analytic.cdf_w(horizon - a) + analytic.partial_mean_w(horizon - a))
               for p, a in zip(p_first, starts)) / p_taken
    return {"missed": 1 - p_taken,
            "alarms_per_dose": 1 + sum(1 - cdf_r(deadline * j) for j in range(1, max_alarms)),
            "lat_mean_s": mean}


def check_closed_form(bench: Path = BENCH) -> None:
    """The generalised form must give the shared file's own numbers for 3 x 300 s."""
    ours, theirs = closed_form(3, 300.0, bench), _analytic(bench).expectations()
    assert math.isclose(ours["missed"] * 100, theirs["miss_pct"], rel_tol=1e-12)
    assert math.isclose(ours["alarms_per_dose"], theirs["alarms_per_dose"], rel_tol=1e-12)
    assert math.isclose(ours["lat_mean_s"], theirs["lat_mean_s"], rel_tol=1e-12)


def four_alarm_spec(folder: Path) -> Path:
    """Design B: the dispenser sounding at most four alarms instead of three."""
    text = SPEC.read_text(encoding="utf-8")
    old = "<Expression>alarms &lt; 3</Expression>"
    if text.count(old) != 1:
        raise SystemExit(f"{SPEC}: expected one '{old}' (the re-alarm condition); the spec "
                         "changed, update benchmarks/interval_coverage.py")
    path = folder / "medication_dispenser_4_alarms.xpdl"
    path.write_text(text.replace(old, "<Expression>alarms &lt; 4</Expression>"),
                    encoding="utf-8")
    return path


# ---------------------------------------------------------------- one repetition
def repetition(spec_b: str, users: int, days: float, seed: int) -> dict[str, Any]:
    """One evaluation of A and B on ``users`` users (seed ``seed``), as ``opspec evaluate
    --compare`` computes it; returns each design's and the difference's (estimate, ci95)."""
    from opspec.evaluation.describe import metric_record
    from opspec.evaluation.plan import Design, EvaluationPlan, file_digest
    from opspec.evaluation.replication import prepare
    from opspec.evaluation.runner import run_evaluation
    from opspec.evaluation.store import ResultStore
    from opspec.evaluation.summary import compare_designs, summarise_design

    designs = (Design("A", str(SPEC), file_digest(SPEC)),
               Design("B", spec_b, file_digest(spec_b)))
    plan = EvaluationPlan(designs=designs, users=users, days=days, seed=seed,
                          user_model=USER_MODEL)
    with tempfile.TemporaryDirectory(prefix="opspec-coverage-") as tmp:
        store = ResultStore(tmp, create=True)
        try:
            store.put("plan", plan.to_json())
            for design in designs:
                context = prepare(design.spec, design.sha256, USER_MODEL, {})
                store.put("metrics" if design.label == "A" else "metrics_B",
                          [metric_record(m) for m in context.compiled.package.metrics])
            outcome = run_evaluation(plan, store, workers=1)
            if outcome.failed:
                raise RuntimeError(f"{outcome.failed} replication(s) failed (seed {seed})")
            out: dict[str, Any] = {}
            for label in ("A", "B"):
                summary = summarise_design(store, label, days)
                out[label] = {m: (summary[m].get("value", summary[m].get("mean")),
                                  summary[m]["ci95"]) for m in METRICS}
            difference = compare_designs(store, "A", "B")
            out["B-A"] = {m: (difference[m]["difference"], difference[m]["ci95"])
                          for m in METRICS}
            return out
        finally:
            store.close()


def _covers(ci: Sequence[float | None], truth: float) -> bool:
    low, high = ci
    return low is not None and high is not None and low <= truth <= high


def acceptance_band(repetitions: int, level: float = 0.95) -> tuple[float, float]:
    """Coverage shares a correct ``level`` interval shows with probability >= 0.95 over
    ``repetitions`` independent repetitions (central binomial range)."""
    from scipy import stats  # type: ignore[import-untyped]

    low = stats.binom.ppf(0.025, repetitions, level) / repetitions
    high = stats.binom.ppf(0.975, repetitions, level) / repetitions
    return float(low), float(high)


def run(repetitions: int, user_counts: Sequence[int], days: float, workers: int,
        seed0: int = 19_000, bench: Path = BENCH) -> dict[str, Any]:
    """Every repetition at every user count; the coverage table as a dict."""
    check_closed_form(bench)
    truth_a, truth_b = closed_form(3, bench=bench), closed_form(4, bench=bench)
    truth = {"A": {m: truth_a[k] for m, k in METRICS.items()},
             "B": {m: truth_b[k] for m, k in METRICS.items()},
             "B-A": {m: truth_b[k] - truth_a[k] for m, k in METRICS.items()}}
    results: dict[int, list[dict[str, Any]]] = {n: [] for n in user_counts}
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="opspec-coverage-spec-") as folder:
        spec_b = str(four_alarm_spec(Path(folder)))
        jobs = [(n, seed0 + 1000 * i + r) for i, n in enumerate(user_counts)
                for r in range(repetitions)]
        if workers <= 1:
            for n, seed in jobs:
                results[n].append(repetition(spec_b, n, days, seed))
        else:
            with cf.ProcessPoolExecutor(max_workers=workers) as pool:
                futures = {pool.submit(repetition, spec_b, n, days, seed): n
                           for n, seed in jobs}
                for future in cf.as_completed(futures):
                    results[futures[future]].append(future.result())
    table = []
    for n in user_counts:
        for part in ("A", "B", "B-A"):
            for metric in METRICS:
                cis = [rep[part][metric][1] for rep in results[n]]
                estimates = [rep[part][metric][0] for rep in results[n]
                             if rep[part][metric][0] is not None]
                covered = sum(_covers(ci, truth[part][metric]) for ci in cis)
                missing = sum(1 for ci in cis if None in ci)
                widths = [ci[1] - ci[0] for ci in cis if None not in ci]
                below = sum(1 for ci in cis if None not in ci and ci[1] < truth[part][metric])
                table.append({"users": n, "design": part, "metric": metric,
                              "truth": truth[part][metric], "coverage": covered / len(cis),
                              "truth_above_interval": below / len(cis),
                              "no_interval": missing,
                              "mean_estimate": (sum(estimates) / len(estimates)
                                                if estimates else None),
                              "mean_width": sum(widths) / len(widths) if widths else None})
    return {"repetitions": repetitions, "days": days, "users": list(user_counts),
            "band": acceptance_band(repetitions), "wall_s": time.perf_counter() - started,
            "truth": truth, "table": table}


def print_table(result: dict[str, Any]) -> None:
    low, high = result["band"]
    print(f"95 % interval coverage over {result['repetitions']} repetitions, "
          f"{result['days']:g} days per user, designs A (3 alarms) and B (4 alarms), "
          f"{result['wall_s']:.0f} s")
    print(f"(a correct 95 % interval lands in [{100 * low:.1f} %, {100 * high:.1f} %] with "
          "probability 0.95; target band 93-97 %)\n")
    print(f"{'users':>5}  {'design':<6}  {'metric':<17}  {'truth':>11}  {'mean est.':>11}  "
          f"{'coverage':>8}  {'truth>hi':>8}  {'no CI':>6}  {'mean width':>11}")
    for row in result["table"]:
        flag = "" if 0.93 <= row["coverage"] <= 0.97 else "  <- outside 93-97 %"
        width = "-" if row["mean_width"] is None else f"{row['mean_width']:.4g}"
        estimate = "-" if row["mean_estimate"] is None else f"{row['mean_estimate']:.5g}"
        print(f"{row['users']:>5}  {row['design']:<6}  {row['metric']:<17}  "
              f"{row['truth']:>11.5g}  {estimate:>11}  {100 * row['coverage']:>7.1f}%  "
              f"{100 * row['truth_above_interval']:>7.1f}%  {row['no_interval']:>6}  "
              f"{width:>11}{flag}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repetitions", type=int, default=200)
    parser.add_argument("--users", type=int, nargs="+", default=[10, 20, 100])
    parser.add_argument("--days", type=float, default=30.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=19_000,
                        help="repetition r at the i-th user count has seed SEED + 1000 i + r "
                             "(default: %(default)s)")
    parser.add_argument("--json", metavar="FILE", help="also write the table as JSON")
    parser.add_argument("--bench", metavar="DIR", default=str(BENCH),
                        help="the folder of SCENARIO.md and analytic.py (default: %(default)s)")
    args = parser.parse_args()
    if not (Path(args.bench) / "analytic.py").is_file():
        parser.error(f"no analytic.py in {args.bench}: give --bench DIR (shared/bench)")
    result = run(args.repetitions, args.users, args.days, args.workers, seed0=args.seed,
                 bench=Path(args.bench))
    print_table(result)
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
