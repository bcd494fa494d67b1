"""Check a user model against people it was not fitted on.

Compare traces or walkthrough recordings of people NOT used to fit MODEL with what MODEL
predicts, per user-lane activity (durations: Anderson-Darling by parametric bootstrap, the
population's between-person spread and the parameters' [uncertainty] included; omission,
commission and repetition rates: exact binomial / beta-binomial) and, with --spec, per outcome
metric of the spec (predictive intervals from runs of the spec with the model). Holm's
adjustment keeps the chance of any false misfit at --level.

Exit status: 0 no item misfits; 1 one does (each named with its statistic, p-value and what
the people did against what the model predicts); 2 a usage or input problem. docs/fitting.md,
Checking a model against new people.
"""
from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.commands import _args
from opspec.usermodels.persons import PERSON_FROM

if TYPE_CHECKING:
    from opspec.usermodels.checking import CheckReport
    from opspec.usermodels.model import UserModel
    from opspec.usermodels.persons import PersonRule

__all__ = ["CheckOptions", "CrossValidation", "add_person_options", "check_model", "check_options",
           "cross_validate", "register", "trace_files"]


def add_person_options(parser: Any, counted: str = "") -> None:
    """``--person``, ``--person-pattern``, ``--person-from``: whose each session is
    (``counted``: where that matters, for the group's description)."""
    who = parser.add_argument_group(
        "whose sessions", "several sessions of one participant are one person"
        + (f": {counted}" if counted else "") + " (docs/fitting.md)")
    who.add_argument("--person", action="append", default=[], metavar="FILE=ID",
                     help="the sessions in FILE are participant ID (repeatable)")
    who.add_argument("--person-pattern", metavar="REGEX",
                     help="the participant is the first group of REGEX found in each file's "
                     "path, e.g. '(P\\d+)' for recordings/P07-day2.jsonl")
    who.add_argument("--person-from", choices=PERSON_FROM, default="auto",
                     help="otherwise: the trace header's 'person' key (header), each file "
                     "(file), its folder's name (folder), each run (run); auto (default): "
                     "the header's key where there is one, else each run")


def register(subparsers: Any) -> None:
    parser = _args.command(subparsers, "model-check", __doc__)
    parser.add_argument("model", metavar="MODEL",
                        help="user model: a TOML file (fitted or hand-written, a population "
                        "included), a preset, or A,B compositions")
    parser.add_argument("traces", nargs="+", metavar="TRACE",
                        help="trace files (.jsonl) of held-out people, or folders of them")
    _args.add_check_options(parser, level_of="the verdict")
    parser.add_argument("--no-parameter-uncertainty", action="store_true",
                        help="ignore the model's [uncertainty] redraws: take its parameters "
                        "as known")
    _args.add_lane(parser, "checked")
    _args.add_seed(parser, what="seed of the simulated groups")
    _args.add_json(parser, "the check as JSON")
    parser.add_argument("--report", metavar="DIR",
                        help="write DIR/model-check.html: the verdict, QQ plots per activity "
                        "and intervals per metric")
    add_person_options(parser, "in the simulated groups the people are compared with")
    parser.set_defaults(handler=_model_check)


@dataclass(frozen=True)
class CheckOptions:
    level: float = 0.05
    replicates: int = 399
    seed: int = 0
    lane: str = "user"
    parameter_uncertainty: bool = True
    spec: str | None = None
    days: float | None = None
    runs: int = 200


class _ComposedDraws:
    """Parameter redraws of the fitted part of a composed reference (``fitted.toml,mci``):
    draw ``d`` is the reference loaded with that part's draw ``d`` (opspec evaluate
    --input-uncertainty's rule)."""

    def __init__(self, ref: str, draws: Any, index: int) -> None:
        self.ref, self.draws, self.index = ref, draws, index
        self.count = draws.count

    def apply(self, model: Any, draw: int) -> Any:
        from opspec.usermodels.uncertainty import drawn_model

        return drawn_model(self.ref, self.draws, self.index, draw)


def _draws(ref: str) -> Any:
    from opspec.usermodels.uncertainty import read_parameter_draws

    found = read_parameter_draws(ref)
    if found is None:
        return None
    draws, index = found
    if "," not in ref:
        return draws
    return _ComposedDraws(ref, draws, index)


def trace_files(values: Sequence[str], command: str) -> list[Path]:
    """The trace files ``values`` name (folders searched with their subfolders,
    :func:`~opspec.usermodels.trace_reader.expand_traces`); the broken-off study sessions
    left out are said on standard error, and no trace at all is a UserModelError."""
    import sys

    from opspec.commands._wrong_file import refuse_misplaced_traces
    from opspec.errors import UserModelError
    from opspec.usermodels.trace_reader import expand_traces

    refuse_misplaced_traces(values, command)
    paths, left_out = expand_traces(values)
    if left_out:
        shown = ", ".join(str(p) for p in left_out[:3]) + (" ..." if len(left_out) > 3 else "")
        print(f"opspec {command}: note: left out {len(left_out)} trace(s) of study sessions "
              f"that broke off and were done again ({shown}); name such a file to read it",
              file=sys.stderr)
    if not paths:
        raise UserModelError("no trace files found in " + ", ".join(values),
                             hint="give .jsonl trace files or folders holding them (their "
                             "subfolders are searched too)")
    return paths


def check_options(options: CheckOptions) -> None:
    from opspec.errors import UserModelError

    if not 0 < options.level < 1:
        raise UserModelError(f"--level must be between 0 and 1, not {options.level:g}",
                             hint="for instance --level 0.05")
    if options.replicates < 19:
        raise UserModelError(f"--replicates must be at least 19, not {options.replicates}",
                             hint="a bootstrap p-value is at least 1/(B+1): take 399 or more "
                             "so that Holm can reach small levels")
    if options.runs < 2:
        raise UserModelError(f"--runs must be at least 2, not {options.runs}")


def check_model(model: UserModel, model_ref: str | None, paths: Sequence[Path],
                options: CheckOptions, persons: PersonRule | None = None) -> CheckReport:
    """Check ``model`` against the traces ``paths`` (what ``opspec model-check`` prints)."""
    from opspec.usermodels.checking import (
        CheckReport,
        check_observations,
        count_decisions,
        finish,
    )
    from opspec.usermodels.fitting import collect

    check_options(options)
    if persons is not None:
        persons.check_used(list(paths))
    from opspec.usermodels.observations import without_lane_text

    obs = collect(paths, options.lane, persons)
    without = without_lane_text(obs, options.lane)
    fitted_on, overlap = _fitted_on_notes(model_ref, obs.persons)
    overlap += [without] if without else []
    draws = (_draws(model_ref) if options.parameter_uncertainty and model_ref else None)
    repeated: dict[str, dict[str, int]] = {}
    traced = False
    if any(a.repetition is not None for a in model.activities.values()):
        repeated, traced = count_decisions(paths, obs)
    items, notes = check_observations(model, obs, replicates=options.replicates,
                                      seed=options.seed, draws=draws, repeated=repeated,
                                      decisions_traced=traced)
    if options.spec is not None:
        from opspec.commands._spec import load_any_spec
        from opspec.evaluation.predictive import (
            metric_items,
            observed_metrics,
            predicted_metrics,
        )

        package = load_any_spec(options.spec, command="model-check")
        notes.extend(_other_spec_notes(paths, options.spec))
        notes.extend(_short_session_notes(paths, package, options.days))
        definitions = package.metrics
        if not definitions:
            notes.append(f"{options.spec} declares no outcome metrics (opspec:Metrics): "
                         "only the activities were checked")
        else:
            observed = observed_metrics(paths, definitions, obs.person_of)
            predicted = predicted_metrics(package, model, runs=options.runs,
                                          seed=options.seed, days=options.days, draws=draws)
            units = {m.name: getattr(m, "unit", None) or "" for m in definitions}
            more, more_notes = metric_items(observed, predicted, seed=options.seed,
                                            units=units)
            items.extend(more)
            notes.extend(more_notes)
    if not items:
        from opspec.errors import UserModelError

        raise UserModelError("nothing to check: the traces hold no activity the model "
                             "describes", hint="check --lane and that MODEL is the model of "
                             "these traces' spec")
    uncertainty = ("none in the model (its parameters taken as known)" if draws is None
                   else f"{draws.count} redraws of its [uncertainty] table, one per "
                   "simulated group")
    if draws is None and not options.parameter_uncertainty:
        uncertainty = "ignored (--no-parameter-uncertainty)"
    return CheckReport(finish(items, options.level), options.level, len(obs.persons),
                       obs.sessions, options.replicates, options.seed, uncertainty,
                       tuple(overlap + notes), fitted_on)


def _fitted_on_notes(model_ref: str | None, persons: Sequence[str]) -> tuple[int, list[str]]:
    """How many people checked are among those the model was fitted on (its
    ``[fitted_on]`` table), and a note naming them: their fit to the model says little of
    new people."""
    from opspec.usermodels.fitted_on import fitted_persons

    fitted = fitted_persons(model_ref)
    if not fitted:
        return 0, []
    both = [p for p in persons if p in set(fitted)]
    if not both:
        return 0, []
    shown = ", ".join(both[:6]) + (" ..." if len(both) > 6 else "")
    note = (f"{len(both)} of the {len(persons)} person(s) checked are among the "
            f"{len(fitted)} the model was fitted on ({shown}; its [fitted_on] table): a check "
            "on them is not a check on new people; give only people left out of the fit")
    return len(both), [note]


def _other_spec_notes(paths: Sequence[Path], spec: str) -> list[str]:
    """A note when traces name (in their header's ``spec``) another spec than ``--spec``:
    a study's variants recorded side by side (recordings/P01/A and B) would have their
    metrics replayed with one spec's definitions and averaged per person."""
    from opspec.usermodels.trace_reader import trace_header

    others: dict[str, list[str]] = {}
    for path in paths:
        recorded = trace_header(path).get("spec")
        if isinstance(recorded, str) and recorded and Path(recorded).stem != Path(spec).stem:
            others.setdefault(Path(recorded).name, []).append(str(path))
    if not others:
        return []
    files = [f for found in others.values() for f in found]
    note = (f"{len(files)} of {len(paths)} trace file(s) were recorded with another spec than "
            f"--spec {spec} ({', '.join(sorted(others))}: {', '.join(files[:3])}"
            f"{' ...' if len(files) > 3 else ''}): their metrics are replayed with this "
            "spec's definitions and averaged with the others per person; check each spec's "
            "traces on their own")
    return [note]


def _short_session_notes(paths: Sequence[Path], package: Any, days: float | None
                         ) -> list[str]:
    """A note naming the traces whose last session does not last the run length the metrics
    are predicted for: a recording cut short (no ``run.ended``: a crash, a kill) or a session
    quit early has fewer doses due, fewer alarms, and a week's session more than a day's
    run; their metrics would be compared with runs of another length (a correct model
    called a misfit of ``doses_due``)."""
    from opspec.engine.trace import EventKind
    from opspec.run_rules import run_length
    from opspec.usermodels.trace_reader import read_trace

    horizon = run_length(package, days=days)
    short: list[str] = []
    for path in paths:
        last, ended = 0.0, False
        for event in read_trace(path):
            if event.kind == EventKind.RUN_STARTED:
                ended = False
            elif event.kind == EventKind.RUN_ENDED:
                ended = True
            last = max(last, event.time) if event.kind != EventKind.RUN_STARTED else 0.0
        if not ended:
            short.append(f"{path} (cut short at {last / 86400:.2f} day(s): no run.ended)")
        elif abs(last - horizon) > 1e-6:
            short.append(f"{path} ({'ends at' if last < horizon else 'runs to'} "
                         f"{last / 86400:.2f} day(s))")
    if not short:
        return []
    note = (f"{len(short)} of {len(paths)} trace file(s) do not last the {horizon / 86400:g} "
            f"day(s) the metrics are predicted for: {'; '.join(short[:3])}"
            f"{' ...' if len(short) > 3 else ''}; their metrics are compared with runs of "
            "another length: give --days as long as the sessions, or leave those traces out "
            "of a metric check")
    return [note]


def _model_check(args: argparse.Namespace) -> int:
    from opspec.commands._wrong_file import refuse_misplaced_model
    from opspec.usermodels.loader import load_user_model
    from opspec.usermodels.persons import PersonRule, parse_person_options

    refuse_misplaced_model(args.model)
    paths = trace_files(args.traces, "model-check")
    if args.report:
        from opspec.commands._files import unwritable
        from opspec.errors import UserModelError

        problem = unwritable(Path(args.report), folder=True)
        if problem is not None:     # said now, not after the check
            raise UserModelError(problem, hint="choose a writable folder with --report")
    model = load_user_model(args.model)
    persons = PersonRule(args.person_from, args.person_pattern,
                         parse_person_options(args.person))
    options = CheckOptions(level=args.level, replicates=args.replicates, seed=args.seed,
                           lane=args.lane,
                           parameter_uncertainty=not args.no_parameter_uncertainty,
                           spec=args.spec, days=args.days, runs=args.runs)
    report = check_model(model, args.model, paths, options, persons)
    written = None
    if args.report:
        from opspec.evaluation.model_check_report import write_report

        # "held-out" only when none of them is known to have been in the fit
        held = "" if report.fitted_on else "held-out "
        written = write_report(report, args.report,
                               title=f"Model check: {args.model} against "
                               f"{report.persons} {held}person(s)")
    if args.json:
        doc = {"model": args.model, "traces": [str(p) for p in paths], **report.to_json(),
               "report": str(written) if written else None}
        print(json.dumps(doc, indent=1))
    else:
        print(f"model {args.model} against {report.persons} person(s), {report.sessions} "
              f"session(s) in {len(paths)} trace file(s)")
        for line in report.lines():
            print(line)
        if written:
            print(f"report: {written}")
    return 0 if report.fits else 1


@dataclass(frozen=True)
class CrossValidation:
    """``opspec fit --holdout K``: per fold, the persons held out and the check of the model
    fitted without them; Holm over every item of every fold gives one verdict."""

    folds: tuple[tuple[tuple[str, ...], CheckReport], ...]
    level: float

    @property
    def items(self) -> list[tuple[int, Any]]:
        return [(f, item) for f, (_, report) in enumerate(self.folds) for item in report.items]

    def adjusted(self) -> list[tuple[int, Any, float]]:
        from opspec.usermodels.holm import holm_adjust

        pairs = self.items
        return [(f, item, a) for (f, item), a in zip(
            pairs, holm_adjust([item.p for _, item in pairs]), strict=True)]

    @property
    def misfits(self) -> list[tuple[int, Any, float]]:
        return [(f, i, a) for f, i, a in self.adjusted() if a <= self.level]

    @property
    def fits(self) -> bool:
        return not self.misfits

    def lines(self) -> list[str]:
        k = len(self.folds)
        out = []
        for f, (held, report) in enumerate(self.folds):
            names = ", ".join(held[:6]) + (" ..." if len(held) > 6 else "")
            # the fold's own Holm is over its items only: what misfits there need not
            # misfit over all folds (the verdict below), and is said to be the fold's
            flagged = (f"misfit within this fold (Holm over its {len(report.items)} "
                       "item(s), not over all folds): "
                       + ", ".join(i.name for i in report.misfits)
                       if report.misfits else "nothing misfits")
            out.append(f"fold {f + 1}/{k}: fitted without {len(held)} person(s) ({names}), "
                       f"checked on them: {flagged}")
        total = len(self.items)
        for f, item, a in self.misfits:
            out.append(f"MISFIT fold {f + 1}: {item.name}: {item.comparison()}; {item.test}, "
                       f"p = {item.p:.3g}; Holm over all folds: p = {a:.3g}")
        verdict = ("the fitted model predicts held-out people: none of "
                   f"{total} item(s) over {k} folds misfits" if self.fits else
                   f"{len(self.misfits)} of {total} item(s) over {k} folds misfit: "
                   + ", ".join(sorted({i.name for _, i, _ in self.misfits})))
        out.append(f"cross-validated verdict ({k}-fold by person; Holm over all {total} "
                   f"items, family-wise level {self.level:g}): {verdict}")
        return out

    def to_json(self) -> dict[str, Any]:
        adjusted = self.adjusted()
        return {"folds": [{"held_out": list(held), **report.to_json()}
                          for held, report in self.folds],
                "level": self.level, "fits": self.fits,
                "family_wise": {"method": "holm", "items": len(adjusted),
                                "over": "every item of every fold"},
                "misfits": [{"fold": f + 1, "item": i.name, "p_holm_all_folds": a}
                            for f, i, a in self.misfits]}


def fold_persons(paths: Sequence[Path], obs: Any, k: int
                 ) -> tuple[dict[int, set[str]], list[str]]:
    """Whose each trace file is (file index -> persons) and the persons, for ``--holdout k``
    over the observations ``obs`` of ``paths``; a UserModelError when they cannot be split
    into ``k`` folds (a file holding several persons, too few persons). ``opspec fit`` asks
    it before it writes anything."""
    from opspec.errors import UserModelError

    files: dict[int, set[str]] = {}
    for (file_index, _), person in obs.person_of.items():
        files.setdefault(file_index, set()).add(person)
    shared = [str(paths[i]) for i, who in files.items() if len(who) > 1]
    if shared:
        raise UserModelError(
            f"--holdout splits by person, but {shared[0]} holds sessions of "
            f"{len(files[paths.index(Path(shared[0]))])} persons",
            hint="give each person's sessions their own files, or say whose a file is "
            "(--person-from file, --person-from header, --person FILE=ID)")
    people = list(obs.persons)

    def splits(folds: int) -> bool:      # each fold a person or more, the rest 3 or more
        return 2 <= folds <= len(people) and len(people) - -(-len(people) // folds) >= 3

    if not splits(k):
        can = [f for f in range(2, len(people) + 1) if splits(f)]
        raise UserModelError(
            f"--holdout {k} cannot split {len(people)} person(s) into folds",
            hint="each fold needs one person or more and the rest three or more to fit on: "
            + (f"use {can[0]} to {can[-1]} folds" if can else
               "that takes 4 persons or more; record more people, or check the model on "
               "people kept apart with `opspec model-check`"))
    return files, people


def cross_validate(paths: Sequence[Path], persons: PersonRule, k: int, *,
                   fit: Any, options: CheckOptions, work: Path) -> CrossValidation:
    """Fit on all persons but one fold, check on that fold, for each of ``k`` folds.
    ``fit(train_paths, model_path, persons)`` writes the model fitted on ``train_paths`` (as ``opspec
    fit`` would); persons are assigned to folds at random (``options.seed``)."""
    import numpy as np

    from opspec.usermodels.fitting import collect
    from opspec.usermodels.loader import load_user_model

    check_options(options)
    files, people = fold_persons(paths, collect(paths, options.lane, persons), k)
    order = [people[i] for i in np.random.default_rng(options.seed).permutation(len(people))]
    folds = []
    for f in range(k):
        held = tuple(sorted(order[f::k]))
        test = [p for i, p in enumerate(paths) if files.get(i, set()) & set(held)]
        train = [p for i, p in enumerate(paths) if not files.get(i, set()) & set(held)]
        model_path = work / f"fold{f + 1}.users.toml"
        fit(train, model_path, _named(train, paths, files))
        model = load_user_model(model_path)
        folds.append((held, check_model(model, str(model_path), test, options,
                                        _named(test, paths, files))))
    return CrossValidation(tuple(folds), options.level)


def _named(subset: Sequence[Path], paths: Sequence[Path], files: dict[int, set[str]]
           ) -> PersonRule:
    """The persons of ``subset`` named file by file (each file is one person's), so a part
    of the traces keeps the persons the whole had."""
    from opspec.usermodels.persons import PersonRule

    index = {str(p): i for i, p in enumerate(paths)}
    return PersonRule("auto", None, {str(p): next(iter(files[index[str(p)]]))
                                     for p in subset if index[str(p)] in files})
