"""How often ``opspec model-check`` calls a correct model a misfit, and how often it catches
a wrong one (docs/fitting.md, *What the check can detect*).

Run: ``OPSPEC_PURE_PYTHON=1 .venv/bin/python benchmarks/model_check_power.py MODE [--reps N]``

Every repetition draws fresh simulated people of specs/medication_dispenser.xpdl (14 days,
4 doses a day) from a known population — the reference user whose median walk varies by
person (lognormal, sigma 0.25) and whose chance of missing an alarm varies by person (beta,
sd 0.08) — and checks them at family-wise level 0.05 (399 bootstrap groups):

* ``true``: 10 people against the true population model: the false-alarm rate;
* ``fitted``: a model fitted (``opspec fit``, its default 200 parameter redraws) on 30
  people, checked on 10 others: the false-alarm rate of the whole fit-then-check procedure;
* ``fitted-power``: the model of ``fitted``'s repetition r against 10 people whose walk is
  1.5x slower, and 10 who miss 30 % of the alarms: the power of the whole procedure;
* ``ttest``: the same 40 people as ``fitted`` (same seeds), each item instead compared by
  the textbook two-sample t-test of the 30 persons' against the 10 persons' own values
  (omission and commission rates, log mean walk and pill times), Holm over the four: how
  many false alarms these particular repetitions hold for a test known to keep its level;
* ``power``: 10 (or 20) people of a different population against the true model, for
  several sizes of misfit: the detection rate, and which items were flagged.

Each rate is printed with its exact (Clopper-Pearson) 95 % interval. ``--start`` and
``--reps`` split the repetitions over processes (each repetition has its own seeds); the
``rep N:`` lines of several runs add up (``tally FILE...`` counts them). ``--detail FILE``
appends each check's items (p-values, and which way the people differed) as JSON lines, with
(``fitted``) the duration family AIC chose per activity and the runner-up's dAIC.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
BASE = ROOT / "specs" / "medication_dispenser.users.toml"
# the populations written below extend BASE from a temporary folder: a user model may name a
# file outside its folder only where OPSPEC_EXTERNAL_PATH allows it
os.environ.setdefault("OPSPEC_EXTERNAL_PATH", str(BASE.parent))
DAYS = 14


def population(directory: Path, name: str, walk_median: float, omission: float) -> Path:
    path = directory / f"{name}.users.toml"
    path.write_text(
        f'name = "{name}"\nextends = "{BASE}"\n'
        "[vary.activities.hear_alarm.omission]\n"
        f'probability = {{ kind = "beta", mean = {omission}, sd = 0.08 }}\n'
        "[vary.activities.walk_to_dispenser.duration]\n"
        f'median = {{ kind = "lognormal", median = {walk_median}, sigma = 0.25 }}\n',
        encoding="utf-8")
    return path


def people(model: Path, directory: Path, count: int, seed: int) -> list[Path]:
    from opspec.evaluation.predictive import write_person_traces

    return write_person_traces(SPEC, model, directory, people=range(count), seed=seed,
                               days=DAYS)


#: where ``check`` appends one JSON line per check (``--detail``), None: nowhere
DETAIL: list[Path] = []


def check(model_path: Path, traces: list[Path], seed: int, **about: object
          ) -> tuple[bool, list[str]]:
    from opspec.commands.model_check import CheckOptions, check_model
    from opspec.usermodels.loader import load_user_model

    report = check_model(load_user_model(model_path), str(model_path), traces,
                         CheckOptions(seed=seed))
    if DETAIL:
        import json

        # per item: p, Holm-adjusted p, and whether the people did more (or took longer)
        # than the model predicts — which way the false alarms go tells a skewed predictive
        items = {i.name: {"p": i.p, "p_holm": i.p_holm, "observed": i.observed["value"],
                          "predicted": i.predicted["value"],
                          "above": i.observed["value"] > i.predicted["value"]}
                 for i in report.items}
        with DETAIL[0].open("a", encoding="utf-8") as out:
            out.write(json.dumps({**about, "seed": seed, "fits": report.fits,
                                  "items": items}) + "\n")
    return report.fits, [i.name for i in report.misfits]


def exact(k: int, n: int) -> str:
    """``k/n`` with its Clopper-Pearson ("exact") 95 % interval (scipy's binomtest)."""
    from scipy.stats import binomtest

    ci = binomtest(k, n).proportion_ci(0.95, method="exact")
    return f"{k}/{n} = {k / n:.3f} (Clopper-Pearson 95 % [{ci.low:.3f}, {ci.high:.3f}])"


def run_true(reps: int, work: Path, start: int = 0) -> None:
    truth = population(work, "truth", 60.0, 0.15)
    alarms, flagged = 0, Counter[str]()
    for r in range(start, start + reps):
        traces = people(truth, work / f"true{r}", 10, seed=10_000 + r)
        fits, names = check(truth, traces, seed=r)
        alarms += not fits
        flagged.update(names)
        print(f"  rep {r}: {'fits' if fits else 'MISFIT ' + ', '.join(names)}", flush=True)
    print(f"true model, 10 people: false alarms {exact(alarms, reps)}; items flagged: "
          f"{dict(flagged)}")


#: the last fitted model's duration families (activity -> (family, dAIC of the runner-up))
FAMILIES: dict[str, tuple[str, float | None]] = {}


def fitted_model(truth: Path, work: Path, r: int) -> tuple[Path, list[Path]]:
    """Repetition ``r``'s model fitted (``opspec fit``, 200 redraws) on 30 people of
    ``truth`` (seed 20,000 + r), and the traces of 10 more people of it."""
    from opspec.commands.fit import fitted_text
    from opspec.usermodels.bootstrap import parameter_draws
    from opspec.usermodels.fitting import fit_traces

    traces = people(truth, work / f"fit{r}", 40, seed=20_000 + r)
    result = fit_traces(traces[:30], name="fitted")
    # the family AIC chose per activity, and how far the runner-up is behind (dAIC): the
    # redraws keep the chosen family, so a close call is where a wrong shape can come from
    FAMILIES.clear()
    FAMILIES.update({f.activity: (f.chosen, round(sorted(f.aic.values())[1]
                                                  - sorted(f.aic.values())[0], 2)
                                  if len(f.aic) > 1 else None)
                     for f in result.fits if f.aic})
    draws = parameter_draws(result, 200, seed=r)
    fitted = work / f"fit{r}" / "fitted.users.toml"
    fitted.write_text(fitted_text(result, draws), encoding="utf-8")
    return fitted, traces[30:]


def run_fitted(reps: int, work: Path, start: int = 0) -> None:
    truth = population(work, "truth", 60.0, 0.15)
    alarms, flagged = 0, Counter[str]()
    for r in range(start, start + reps):
        fitted, held_out = fitted_model(truth, work, r)
        fits, names = check(fitted, held_out, seed=r, mode="fitted", rep=r,
                            families=dict(FAMILIES))
        alarms += not fits
        flagged.update(names)
        print(f"  rep {r}: {'fits' if fits else 'MISFIT ' + ', '.join(names)}", flush=True)
    print(f"fitted on 30, checked on 10: false alarms {exact(alarms, reps)}; items "
          f"flagged: {dict(flagged)}")


FITTED_SIZES = (("walk 1.5x slower", 90.0, 0.15), ("30 % of alarms missed", 60.0, 0.30))


def run_fitted_power(reps: int, work: Path, start: int = 0) -> None:
    """The power of fit-then-check: repetition r's fitted model (as ``fitted``) against 10
    people of a population whose walk is 1.5x slower, and 10 who miss 30 % of the alarms
    (seed 30,000 + r)."""
    truth = population(work, "truth", 60.0, 0.15)
    others = [(label, population(work, f"other{i}", walk, omission))
              for i, (label, walk, omission) in enumerate(FITTED_SIZES)]
    caught, flagged = Counter[str](), {label: Counter[str]() for label, _ in others}
    for r in range(start, start + reps):
        fitted, _ = fitted_model(truth, work, r)
        for index, (label, other) in enumerate(others):
            traces = people(other, work / f"power{index}-{r}", 10, seed=30_000 + r)
            fits, names = check(fitted, traces, seed=r, mode="fitted-power", rep=r,
                                misfit=label)
            caught[label] += not fits
            flagged[label].update(names)
            print(f"  {label}, rep {r}: {'fits' if fits else 'MISFIT ' + ', '.join(names)}",
                  flush=True)
    for label, _ in others:
        print(f"fitted on 30, {label}, 10 people: detected {exact(caught[label], reps)}; "
              f"flagged {dict(flagged[label])}")


def run_ttest(reps: int, work: Path, start: int = 0) -> None:
    import numpy as np
    from scipy import stats

    from opspec.usermodels.checking import commission_counts
    from opspec.usermodels.fitting import collect
    from opspec.usermodels.holm import holm_adjust

    truth = population(work, "truth", 60.0, 0.15)
    alarms, flagged = 0, Counter[str]()
    for r in range(start, start + reps):
        obs = collect(people(truth, work / f"fit{r}", 40, seed=20_000 + r))
        omitted = obs.counts_by_person(obs.user_omissions["hear_alarm"])
        picks = obs.lists_by_person(obs.user_picks["choose_button"])
        walks = obs.lists_by_person(obs.user_durations["walk_to_dispenser"])
        pills = obs.lists_by_person(obs.user_durations["take_pill"])
        own = {"hear_alarm omission": lambda p: omitted[p][0] / omitted[p][1],
               "choose_button commission": lambda p: (lambda w, n: w / n)(
                   *commission_counts(picks[p], "press_report", 1)),
               "walk_to_dispenser duration": lambda p: float(np.log(walks[p]).mean()),
               "take_pill duration": lambda p: float(np.log(pills[p]).mean())}
        fitted, checked = obs.persons[:30], obs.persons[30:]
        names = list(own)
        ps = [stats.ttest_ind([own[n](p) for p in checked],
                              [own[n](p) for p in fitted]).pvalue for n in names]
        hit = [n for n, a in zip(names, holm_adjust(ps), strict=True) if a <= 0.05]
        alarms += bool(hit)
        flagged.update(hit)
        print(f"  rep {r}: {'fits' if not hit else 'MISFIT ' + ', '.join(hit)}", flush=True)
    print(f"two-sample t-tests, 30 against 10: false alarms {exact(alarms, reps)}; items "
          f"flagged: {dict(flagged)}")


SIZES = (  # (label, walk median, omission mean, people)
    ("walk 1.2x slower", 72.0, 0.15, 10),
    ("walk 1.2x slower", 72.0, 0.15, 20),
    ("walk 1.5x slower", 90.0, 0.15, 10),
    ("30 % of alarms missed (model: 15 %)", 60.0, 0.30, 10),
    ("20 % of alarms missed (model: 15 %)", 60.0, 0.20, 10),
)


def run_power(reps: int, work: Path) -> None:
    truth = population(work, "truth", 60.0, 0.15)
    rows = []
    for index, (label, walk, omission, count) in enumerate(SIZES):
        other = population(work, f"other{index}", walk, omission)
        caught, flagged = 0, Counter[str]()
        for r in range(reps):
            traces = people(other, work / f"power{index}-{r}", count, seed=30_000 + r)
            fits, names = check(truth, traces, seed=r)
            caught += not fits
            flagged.update(names)
            print(f"  {label}, {count} people, rep {r}: "
                  f"{'fits' if fits else 'MISFIT ' + ', '.join(names)}", flush=True)
        rows.append((label, count, exact(caught, reps), dict(flagged)))
        print(f"{label}, {count} people: detected {exact(caught, reps)}; flagged "
              f"{dict(flagged)}", flush=True)
    print("\n| misfit | people | detected (power) | items flagged |\n|---|---|---|---|")
    for label, count, rate, flagged in rows:
        print(f"| {label} | {count} | {rate} | "
              + ", ".join(f"{k} {v}" for k, v in flagged.items()) + " |")


def tally(paths: list[str]) -> None:
    """The false-alarm rate of the ``rep N:`` lines of earlier runs' outputs (one mode's)."""
    import re

    seen: dict[int, list[str]] = {}
    for path in paths:
        for line in Path(path).read_text(encoding="utf-8").splitlines():
            found = re.match(r"\s+rep (\d+): (fits|MISFIT (.*))$", line)
            if found:
                seen[int(found.group(1))] = ([] if found.group(2) == "fits"
                                             else found.group(3).split(", "))
    flagged = Counter(name for names in seen.values() for name in names)
    alarms = sum(1 for names in seen.values() if names)
    print(f"{len(seen)} repetitions: false alarms {exact(alarms, len(seen))}; items "
          f"flagged: {dict(flagged)}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("mode", choices=("true", "fitted", "fitted-power", "ttest", "power",
                                         "tally"))
    parser.add_argument("outputs", nargs="*", help="tally: the outputs of earlier runs")
    parser.add_argument("--reps", type=int, default=100)
    parser.add_argument("--start", type=int, default=0,
                        help="true, fitted, ttest: the first repetition (to split the "
                        "repetitions over processes)")
    parser.add_argument("--detail", metavar="FILE",
                        help="append one JSON line per check: every item's p-value, "
                        "Holm-adjusted p-value and whether the people were above the model")
    args = parser.parse_args()
    if args.detail:
        DETAIL.append(Path(args.detail))
    start = time.perf_counter()
    if args.mode == "tally":
        tally(args.outputs)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        if args.mode == "power":
            run_power(args.reps, Path(tmp))
        else:
            modes = {"true": run_true, "fitted": run_fitted, "ttest": run_ttest,
                     "fitted-power": run_fitted_power}
            modes[args.mode](args.reps, Path(tmp), args.start)
    print(f"({time.perf_counter() - start:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
