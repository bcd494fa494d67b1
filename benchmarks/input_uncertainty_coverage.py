"""Does `opspec evaluate --input-uncertainty` cover the TRUE model's metric? (issue 19)

    python benchmarks/input_uncertainty_coverage.py [--repetitions 100] [--trace-days 7]
        [--users 100] [--days 5] [--draws 20] [--users-per-draw 10] [--workers 2]

A user model fitted from few observations is wrong by its sampling error, and an evaluation
of the fitted model is then wrong by that much too, however many users it simulates. Each
repetition here does what a researcher does, with a known truth:

1. records ``--trace-days`` days of ONE person following the reference user model
   (``dispenser-reference``: SCENARIO.md's user; 7 days = 28 doses, some 33 alarms and 28
   walks) on the reference dispenser (``specs/medication_dispenser.xpdl``), with its own seed;
2. fits a model to that trace with ``opspec fit --draws B``: the B bootstrap redraws of the
   fitted parameters that step 3 uses (the redraws are one seeded sequence, so they are the
   first B of the 200 a plain ``opspec fit`` writes: the same numbers, without fitting the
   180 redraws evaluate never reads -- most of a repetition's CPU);
3. evaluates the fitted model with ``opspec evaluate --users U --days D
   --input-uncertainty B`` (the same plan, runner and summaries, without the report).

The truth is the closed form of SCENARIO.md at the reference parameters (``analytic.py`` of
``../shared/bench``: 1.1762 alarms per dose, 122.2 s mean report latency, 0.3456 % missed),
i.e. the metric of the TRUE model. It prints per metric how often the ordinary 95 %
interval (simulation noise only), the interval with parameter uncertainty and the direct
bootstrap's percentile interval covered the truth, with the binomial band of a correct 95 %
interval over this many repetitions. The missed rate is shown but not judged: with 28 walks
the fitted walk time's tail (which alone makes a dose missed when heard) is an
extrapolation no bootstrap of 28 values can be trusted to bound. With 4 days (16 doses)
one person in 20 omits no alarm at all: the fit then writes no omission, nothing of it is
redrawn, and those repetitions cannot cover.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import contextlib
import importlib.util
import io
import json
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT.parent / "shared" / "bench"
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
TRUE_MODEL = "dispenser-reference"

#: metric of the evaluation -> key of the closed form
METRICS = {"alarms_per_dose": "alarms_per_dose", "report_latency_s": "lat_mean_s",
           "missed_rate": "missed"}
JUDGED = ("alarms_per_dose", "report_latency_s")
INTERVALS = ("ci95", "ci95_with_parameters", "direct_bootstrap_ci95")


def _coverage_module() -> Any:
    """benchmarks/interval_coverage.py: the closed form, checked against the shared file."""
    path = ROOT / "benchmarks" / "interval_coverage.py"
    spec = importlib.util.spec_from_file_location("interval_coverage", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def record_trace(path: Path, days: float, seed: int) -> Path:
    """``opspec run SPEC --user-model dispenser-reference --days D --seed S --trace PATH``."""
    from opspec.cli import main

    with contextlib.redirect_stdout(io.StringIO()):
        code = main(["run", str(SPEC), "--user-model", TRUE_MODEL, "--days", str(days),
                     "--seed", str(seed), "--trace", str(path), "--timeline", "none"])
    if code not in (0, 1):
        raise RuntimeError(f"opspec run failed ({code}) for seed {seed}")
    return path


def fit(trace: Path, out: Path, seed: int, draws: int = 200) -> Path:
    """``opspec fit TRACE -o OUT --seed S --draws B``."""
    from opspec.cli import main

    with contextlib.redirect_stdout(io.StringIO()):
        code = main(["fit", str(trace), "-o", str(out), "--seed", str(seed),
                     "--draws", str(draws)])
    if code != 0:
        raise RuntimeError(f"opspec fit failed ({code}) on {trace}")
    return out


def evaluate(model: Path, users: int, days: float, draws: int, per_draw: int, seed: int
             ) -> dict[str, Any]:
    """``opspec evaluate SPEC --user-model MODEL --input-uncertainty B`` without the report:
    per metric the ordinary and the widened intervals."""
    from opspec.evaluation.describe import metric_record
    from opspec.evaluation.input_uncertainty import check_draws, summarise_input_uncertainty
    from opspec.evaluation.plan import Design, EvaluationPlan, file_digest
    from opspec.evaluation.replication import prepare
    from opspec.evaluation.runner import run_evaluation
    from opspec.evaluation.store import ResultStore
    from opspec.evaluation.summary import summarise_design

    design = Design("A", str(SPEC), file_digest(SPEC))
    plan = EvaluationPlan(designs=(design,), users=users, days=days, seed=seed,
                          user_model=str(model), input_uncertainty=draws,
                          users_per_draw=per_draw)
    check_draws(plan)
    with tempfile.TemporaryDirectory(prefix="opspec-iu-") as tmp:
        store = ResultStore(tmp, create=True)
        try:
            store.put("plan", plan.to_json())
            context = prepare(design.spec, design.sha256, str(model), {})
            store.put("metrics", [metric_record(m) for m in context.compiled.package.metrics])
            outcome = run_evaluation(plan, store, workers=1)
            if outcome.failed:
                raise RuntimeError(f"{outcome.failed} replication(s) failed (seed {seed})")
            metrics = summarise_design(store, "A", days)
            summary = summarise_input_uncertainty(store, plan, metrics)
            assert summary is not None
            return {m: {k: summary["metrics"][m][k] for k in
                        (*INTERVALS, "estimate", "parameter_share")} for m in METRICS}
        finally:
            store.close()


def repetition(index: int, trace_days: float, users: int, days: float, draws: int,
               per_draw: int, seed0: int) -> dict[str, Any]:
    seed = seed0 + index
    with tempfile.TemporaryDirectory(prefix="opspec-iu-rep-") as tmp:
        trace = record_trace(Path(tmp) / "person.jsonl", trace_days, seed)
        model = fit(trace, Path(tmp) / "fitted.users.toml", seed, draws)
        return evaluate(model, users, days, draws, per_draw, seed + 500_000)


def _covers(ci: Sequence[float | None] | None, truth: float) -> bool:
    return bool(ci) and ci[0] is not None and ci[1] is not None and ci[0] <= truth <= ci[1]


def run(repetitions: int = 100, trace_days: float = 7.0, users: int = 100, days: float = 5.0,
        draws: int = 20, per_draw: int = 10, workers: int = 1, seed0: int = 19_190,
        bench: Path = BENCH) -> dict[str, Any]:
    coverage = _coverage_module()
    coverage.check_closed_form(bench)
    closed = coverage.closed_form(3, bench=bench)
    truth = {m: closed[k] for m, k in METRICS.items()}
    started = time.perf_counter()
    args = (trace_days, users, days, draws, per_draw, seed0)
    if workers <= 1:
        results = [repetition(i, *args) for i in range(repetitions)]
    else:
        with cf.ProcessPoolExecutor(max_workers=workers) as pool:
            results = list(pool.map(repetition, range(repetitions),
                                    *([a] * repetitions for a in args)))
    table = []
    for metric, true in truth.items():
        row: dict[str, Any] = {"metric": metric, "truth": true, "judged": metric in JUDGED}
        for which in INTERVALS:
            cis = [r[metric][which] for r in results]
            row[which] = sum(_covers(ci, true) for ci in cis) / len(cis)
            widths = [ci[1] - ci[0] for ci in cis if ci and None not in ci]
            row[f"{which}_mean_width"] = sum(widths) / len(widths) if widths else None
        shares = [r[metric]["parameter_share"] for r in results
                  if r[metric]["parameter_share"] is not None]
        row["mean_parameter_share"] = sum(shares) / len(shares) if shares else None
        table.append(row)
    return {"repetitions": repetitions, "trace_days": trace_days, "users": users,
            "days": days, "draws": draws, "users_per_draw": per_draw,
            "band": coverage.acceptance_band(repetitions),
            "wall_s": time.perf_counter() - started, "table": table,
            "detail": results}      # every repetition's estimates and intervals


def print_table(result: dict[str, Any]) -> None:
    low, high = result["band"]
    print(f"Coverage of the TRUE model's metric over {result['repetitions']} repetitions: "
          f"one person recorded for {result['trace_days']:g} days, fitted, evaluated with "
          f"{result['users']} users x {result['days']:g} days + {result['draws']} draws x "
          f"{result['users_per_draw']} users ({result['wall_s']:.0f} s)")
    print(f"(a correct 95 % interval covers in [{100 * low:.1f} %, {100 * high:.1f} %] with "
          "probability 0.95)\n")
    print(f"{'metric':<17} {'truth':>9}  {'ordinary':>8}  {'+params':>8}  {'direct':>8}  "
          f"{'width ord.':>10}  {'width +p':>9}  {'from params':>11}")
    for row in result["table"]:
        note = "" if row["judged"] else "  (not judged: see the docstring)"
        print(f"{row['metric']:<17} {row['truth']:>9.4g}  {100 * row['ci95']:>7.1f}%  "
              f"{100 * row['ci95_with_parameters']:>7.1f}%  "
              f"{100 * row['direct_bootstrap_ci95']:>7.1f}%  "
              f"{row['ci95_mean_width']:>10.4g}  {row['ci95_with_parameters_mean_width']:>9.4g}"
              f"  {100 * (row['mean_parameter_share'] or 0):>10.0f}%{note}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repetitions", type=int, default=100)
    parser.add_argument("--trace-days", type=float, default=7.0)
    parser.add_argument("--users", type=int, default=100)
    parser.add_argument("--days", type=float, default=5.0)
    parser.add_argument("--draws", type=int, default=20)
    parser.add_argument("--users-per-draw", type=int, default=10)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", metavar="FILE", help="also write the table as JSON")
    parser.add_argument("--bench", default=str(BENCH), metavar="DIR",
                        help="the folder of analytic.py (default: %(default)s)")
    args = parser.parse_args()
    if not (Path(args.bench) / "analytic.py").is_file():
        parser.error(f"no analytic.py in {args.bench}: give --bench DIR (shared/bench)")
    result = run(args.repetitions, args.trace_days, args.users, args.days, args.draws,
                 args.users_per_draw, args.workers, bench=Path(args.bench))
    print_table(result)
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1), encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
