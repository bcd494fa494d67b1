"""The evaluation report: ``report.html`` (self-contained, rendered from a Jinja2 template a
researcher can replace) and ``report.md`` with its figures (SVG by default, ``--figures``),
built from the result store alone (so a resumed or re-reported run gives the same report).

What a reader gets, in order: key findings in plain words (estimates with their intervals,
hazards); what was run; what each metric measures (from which event to which event a
duration runs, what a count counts); who the simulated users are (every user-model
parameter, with its source); the estimates (table and figure, each rate on its own scale);
how users differ (each user's own rate or mean duration: a table and histograms); each
duration's distribution; counts day by day and by hour (each on its own scale); the user's
actions per activity; hazards from the spec's monitors (or that none were declared); with
two designs the paired differences; failed replications; how to read the intervals.

Figures and tables show the same numbers: every figure is drawn once per metric from the
same summaries as the tables; where a figure draws a sample of many observations its
caption says so, and the marks in it (mean, median, p95) are of all observations.

This module writes the page and puts its sections in that order (what was run, the
comparison, the failures and the interval methods are its own); the others come from
:mod:`.report_findings` (the key findings in words), :mod:`.report_users` (who the users
are) and :mod:`.report_design` (each design's estimates, spread, durations, counts, actions
and hazards). :mod:`.html` renders the sections as HTML and markdown, :mod:`.plots` draws
the figures; those that need neither the sample index nor the summaries can be asked for
before the report is written (:func:`ask_figures_ahead`), to be drawn meanwhile.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.errors import EvaluationError
from opspec.evaluation.describe import describe_metric
from opspec.evaluation.no_spread_notes import figure_marks, no_spread_note
from opspec.evaluation.plan import span
from opspec.evaluation.report_design import (
    PLOT_SAMPLE,
    AskedAhead,
    ask_ahead,
    design_sections,
)
from opspec.evaluation.report_findings import key_findings, metric_label, population_findings
from opspec.evaluation.report_users import user_model_as_run, user_model_section
from opspec.evaluation.run_command import rerun_command
from opspec.evaluation.store import ResultStore
from opspec.evaluation.summary import (
    compare_designs,
    metric_definitions,
    summarise_design,
    summarise_monitors,
    summarise_population,
)
from opspec.evaluation.tables import (
    NO_DURATION_INTERVAL,
    comparison_rows,
    in_percent,
    no_interval_reason,
    subgroup_comparison_rows,
)

if TYPE_CHECKING:
    from opspec.evaluation.figure_queue import FiguresAhead

__all__ = ["PLOT_SAMPLE", "ReportAhead", "Summaries", "ask_figures_ahead", "write_report"]

#: What the evaluate command has already computed, per design label: ``metrics``,
#: ``monitors``; and ``difference`` for a comparison. Passed in so nothing is computed twice.
Summaries = Mapping[str, Any]


def _users_done(store: ResultStore, design: str) -> int:
    return int(store.query("SELECT COUNT(*) FROM replication WHERE design = ? AND "
                           "status = 'done'", (design,))[0][0])


def _with_selectors(store: ResultStore, design: str, spec: str | None, sha256: str | None
                    ) -> list[dict[str, Any]]:
    """The stored definitions; stores written before selectors were kept get them from the
    spec when it is still the file the run used."""
    definitions = [dict(d) for d in metric_definitions(store, design)]
    if not definitions or all("select" in d for d in definitions) or not spec:
        return definitions
    try:
        from opspec.evaluation.describe import metric_record
        from opspec.evaluation.plan import file_digest
        from opspec.xpdl.loader import load_spec

        if sha256 and file_digest(spec) != sha256:
            return definitions
        declared = {m.name: metric_record(m) for m in load_spec(spec).metrics}
    except Exception:  # noqa: BLE001 - a report without the detail is still a report
        return definitions
    return [{**declared.get(d["name"], {}), **{k: v for k, v in d.items() if v is not None}}
            for d in definitions]


def _methods_section(summaries: Any, sections: Sequence[Any]) -> Any:
    """How every interval in the report was computed: each method that appears in it, with
    its recipe and references (the same words as ``--json`` and docs/evaluation.md), so the
    report stands on its own."""
    from opspec.evaluation.html import Section, Table
    from opspec.statistics.methods import METHODS, methods_in

    named = {m.name: m.id for m in METHODS.values()}
    shown = {named[row[i]] for section in sections for table in section.tables
             if "CI method" in table.headers
             for row in table.rows for i in [table.headers.index("CI method")]
             if i < len(row) and row[i] in named}
    used = [m for m in METHODS if m in shown or m in methods_in(summaries)]
    rows = tuple((METHODS[m].name, METHODS[m].definition, "; ".join(METHODS[m].references))
                 for m in used)
    return Section("How the intervals were computed", paragraphs=(
        ("Every interval is a two-sided 95 % confidence interval. The simulated users are the "
         "independent units: observations within one user are not independent (a slow walker "
         "is slow every time), so each metric is reduced to one pair (y, n) per user and "
         "the intervals are over users. The 'CI method' column of each table names the "
         "method below; an interval of something that cannot be negative is cut at zero. "
         "Medians and p95 of durations are of all pooled observations, by linear "
         "interpolation; per-user percentiles are of the users' own values."),),
        tables=(Table(("method", "definition", "references"), rows,
                      "The interval methods used in this report"),) if rows else ())


def _metrics_caption(definitions: Sequence[Mapping[str, Any]]) -> str:
    """Whose metrics these are: the spec's, or opspec's defaults for a spec declaring none."""
    from opspec.model.default_metrics import is_default

    if not definitions:
        return ("The spec declares no metrics (opspec:Metrics) and has no process to measure: "
                "nothing was estimated")
    if all(is_default(d.get("description")) for d in definitions):
        return ("The spec declares no metrics (opspec:Metrics): opspec measured each process "
                "by default, its completed instances and their cycle time, from each user's "
                "trace (declare your own to measure what matters: docs/evaluation.md, Default "
                "metrics)")
    return "Metrics the spec declares (opspec:Metrics), computed from each user's trace"


def _no_interval_words(difference: Mapping[str, Any]) -> str:
    """Why a difference of durations has no interval ('–'), when one has none: '–' is the
    paired method's answer (:func:`opspec.statistics.paired_difference`), not a number left
    out, and a count beside it with a zero difference still has an interval."""
    bare = [n for n, d in difference.items() if no_interval_reason(d) == NO_DURATION_INTERVAL]
    if not bare:
        return ""
    return (f" {', '.join(bare)} {'has' if len(bare) == 1 else 'have'} no interval ('–'): "
            "fewer than 2 users' durations differ between the designs (on the same users and "
            "random streams the others are identical), and a paired interval of durations "
            "rests on the users who differ, so the data cannot say how much the designs "
            "differ; a count with no difference still has an interval, the exact Poisson "
            "bounds of the events that could have differed.")


@dataclass(frozen=True)
class ReportAhead:
    """The report's figures asked for before it is written (:func:`ask_figures_ahead`): the
    figures' queue, per design described what was computed and asked for, and the run's
    user model as it was read for them (None: none, or not the file the run used)."""

    figures: FiguresAhead
    designs: Mapping[str, AskedAhead]
    user_model: Any = None


def ask_figures_ahead(store: ResultStore, *, figures: str = "svg", workers: int = 1
                      ) -> ReportAhead:
    """Ask, for every design the report describes, for its figures that need neither the
    sample index nor the summaries (:func:`.report_design.ask_ahead`), to be drawn by the
    drawing processes while the caller builds them; :func:`write_report` given the result
    asks for the others and waits for all. ``opspec evaluate --workers W`` calls it as soon
    as the last replication is stored (``figures`` and ``workers`` as it then gives
    :func:`write_report`). A design whose reads fail is left out, with those after it: the
    report reads them again and fails where it does without this."""
    from opspec.evaluation import plots

    plan: dict[str, Any] = store.get("plan") or {}
    days = float(plan.get("days", 1))
    designs = [d["label"] for d in plan.get("designs", [])] or ["A"]
    specs = {d["label"]: d["spec"] for d in plan.get("designs", [])}
    digests = {d["label"]: d.get("sha256") for d in plan.get("designs", [])}
    asked: dict[str, AskedAhead] = {}
    model = user_model_as_run(store, plan)      # which activities it can do wrongly
    with plots.figure_format(figures), plots.asked_ahead(workers) as queued:
        # a sweep's report describes its first value only (as _report_sections)
        for design in designs[:1] if store.get("sweep") else designs:
            try:
                definitions = _with_selectors(store, design, specs.get(design),
                                              digests.get(design))
                asked[design] = ask_ahead(store, store.folder / "figures", design, days,
                                          _users_done(store, design), definitions,
                                          user_model=model)
            except EvaluationError:
                break
    return ReportAhead(queued, asked, model)


def prepare_report(template: str | Path | None = None) -> None:
    """Load now what writing the report and its summaries will need: the summaries'
    modules and interval functions (scipy.special) and the HTML template, read and
    compiled. ``opspec evaluate --workers W`` calls it while its workers run the
    replications, when this process is mostly waiting; nothing it does changes a number or
    a word of the report, and what fails here (an unreadable template) fails again when the
    report is written, with its message."""
    from opspec.evaluation import design_summary  # noqa: F401 - loaded for the summaries
    from opspec.evaluation.html import prepare_template
    from opspec.statistics.intervals import t_quantile

    t_quantile(0.95, 1)
    with contextlib.suppress(EvaluationError):
        prepare_template(template)


def write_report(store: ResultStore, summaries: Mapping[str, Summaries] | None = None, *,
                 template: str | Path | None = None, figures: str = "svg",
                 workers: int = 1, ahead: ReportAhead | None = None) -> Path:
    """Write ``report.html``, ``report.md`` and ``figures/*.svg`` (or ``.pdf`` beside SVG
    twins, or ``.png``: ``figures``, :data:`opspec.evaluation.plots.FORMATS`) into the
    store's folder.

    ``summaries`` per design label (``metrics``, ``monitors``; ``difference`` under ``"B"``)
    are what the caller already computed; what is missing is computed here. ``template`` is
    a Jinja2 template to render the HTML with instead of the bundled one. The figures are
    drawn by up to ``workers`` processes side by side (:func:`.plots.drawn_by`); ``ahead``:
    those :func:`ask_figures_ahead` asked for with the same store, ``figures`` and
    ``workers``, not asked for again.
    """
    from opspec.evaluation import plots
    from opspec.evaluation.html import write_html, write_markdown

    with plots.figure_format(figures):
        with plots.drawn_by(workers, ahead.figures if ahead is not None else None):
            title, sections = _report_sections(store, summaries, ahead)
        write_markdown(store.folder / "report.md", title, sections)
        return write_html(store.folder / "report.html", title, sections, template=template)


def _report_sections(store: ResultStore, summaries: Mapping[str, Summaries] | None,
                     asked: ReportAhead | None) -> tuple[str, list[Any]]:
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table

    ahead = asked.designs if asked is not None else {}

    summaries = summaries or {}
    folder = store.folder
    figures = folder / "figures"
    plan: dict[str, Any] = store.get("plan") or {}
    days = float(plan.get("days", 1))
    designs = [d["label"] for d in plan.get("designs", [])] or ["A"]
    specs = {d["label"]: d["spec"] for d in plan.get("designs", [])}
    digests = {d["label"]: d.get("sha256") for d in plan.get("designs", [])}
    names = {label: Path(specs.get(label, "spec")).name for label in designs}
    if len(set(names.values())) < len(names):         # two files of the same name
        names = {label: specs.get(label, label) for label in designs}
    if len(set(names.values())) < len(names):         # a design compared with itself
        names = {label: f"{name} ({'first' if i == 0 else 'second'})"
                 for i, (label, name) in enumerate(names.items())}
    # a sweep (--sweep): its designs are the parameter's values, named by them; the
    # detailed sections describe the first value, the sweep's own sections the others
    sweep = summaries.get("sweep")
    if sweep is None and store.get("sweep"):
        from opspec.evaluation.sweep import Sweep, summarise_sweep

        sweep = summarise_sweep(store, Sweep.from_json(store.get("sweep")), days)
    detailed = designs[:1] if sweep else designs
    if sweep:
        names = {v["design"]: f"{sweep['parameter']} = {v['text']}" for v in sweep["values"]}
    done = {d: _users_done(store, d) for d in designs}
    failures = store.failures()

    per_design: dict[str, tuple[dict[str, Any], dict[str, Any], list[dict[str, Any]]]] = {}
    for design in detailed:
        given = summaries.get(design) or {}
        metrics = given.get("metrics")
        if metrics is None:
            metrics = summarise_design(store, design, days)
        monitors = given.get("monitors")
        if monitors is None:
            monitors = summarise_monitors(store, design, days)
        definitions = _with_selectors(store, design, specs.get(design), digests.get(design))
        per_design[design] = (metrics, monitors, definitions)

    given_a = summaries.get(designs[0]) or {}
    population = (given_a["population"] if "population" in given_a
                  else summarise_population(store, days, designs=detailed))

    sections: list[Any] = []
    metrics_a, monitors_a, definitions_a = per_design[designs[0]]
    findings = key_findings(done.get(designs[0], 0), days, metrics_a, definitions_a,
                            monitors_a, names[designs[0]])
    findings += population_findings(metrics_a, population)
    difference: dict[str, Any] | None = None
    if "B" in designs:
        difference = (summaries.get("B") or {}).get("difference")
        if difference is None:
            difference = compare_designs(store)
        differs = [n for n, d in difference.items() if d.get("significant")]
        findings.append(f"Compared with {names['B']} on the same users: "
                        + (f"{', '.join(differs)} differ (95 % intervals of the paired "
                           "differences exclude zero)." if differs
                           else "no metric differs (every 95 % interval of the paired "
                           "differences includes zero)."))
    if sweep:
        findings += [a["answer"] for a in sweep["targets"]]
        findings += [a["users_answer"] for a in sweep["targets"] if a.get("users_answer")]
    if failures:
        findings.append(f"{len(failures)} replication(s) failed and are left out of every "
                        "number (listed at the end).")
    sections.append(Section("Key findings", paragraphs=(findings[0],),
                            items=tuple(findings[1:])))

    total_users = plan.get("users")
    software = (f"Python {store.get('python_version')}, NumPy {store.get('numpy_version')}"
                if store.get("numpy_version") else None)
    # the files' digests: a reader can tell that a spec is the one the numbers are of
    run_rows = [("specification", specs.get("A", "?")),
                ("specification SHA-256", str(digests.get("A")))]
    if "B" in specs:
        run_rows += [("compared with", specs["B"]),
                     ("compared specification SHA-256", str(digests.get("B")))]
    if sweep:
        run_rows.append(("swept", f"{sweep['parameter']} = "
                         + ", ".join(v["text"] for v in sweep["values"])))
    finished = "; ".join(f"{done[d]:,} of {total_users:,}" + (f" ({names[d]})"
                                                              if len(designs) > 1 else "")
                         for d in designs) if isinstance(total_users, int) else str(done)
    run_rows += [("simulated users", f"{total_users:,}" if isinstance(total_users, int)
                  else str(total_users)),
                 ("simulated time per user", span(days)),
                 ("seed", str(plan.get("seed"))),
                 ("user model", str(plan.get("user_model") or "none")),
                 *([("user model SHA-256", str(store.get("user_model_sha256")))]
                   if store.get("user_model_sha256") else []),
                 ("users finished", finished),
                 ("replications failed", str(len(failures))),
                 ("opspec version", str(store.get("opspec_version"))),
                 *([("Python and NumPy versions", software)] if software else []),
                 ("started", str(store.get("started")))]
    command = rerun_command(plan, swept=bool(sweep))
    if command is not None:
        run_rows.append(("command (the same results with any --workers)", command))
    sections.append(Section("What was run", paragraphs=(
        "Each simulated user is an independent replication with their own random streams"
        + ("; the designs are compared on the same users (common random numbers)."
           if len(designs) > 1 else "."),), tables=(Table(("parameter", "value"),
                                                          tuple(run_rows)),)))
    if sweep:
        from opspec.evaluation.sweep import report_sections

        sections += report_sections(sweep, figures, done.get(designs[0], 0))

    for design in detailed:
        definitions = per_design[design][2]
        suffix = f" ({names[design]})" if len(detailed) > 1 else ""
        sections.append(Section(f"What each metric measures{suffix}", tables=(Table(
            ("metric", "kind", "definition"),
            tuple((d["name"], str(d["kind"]), describe_metric(d)) for d in definitions),
            _metrics_caption(definitions)),)))
    sections.append(user_model_section(store, plan, figures, population))

    # which activities it can do wrongly (read once: as the figures asked ahead read it)
    model = asked.user_model if asked is not None else user_model_as_run(store, plan)
    for design in detailed:
        metrics, monitors, definitions = per_design[design]
        prefix = f"{names[design]}: " if len(detailed) > 1 or sweep else ""
        sections += design_sections(store, figures, design, names[design], days,
                                    done.get(design, 0), metrics, monitors, definitions,
                                    prefix, population, designs[0], ahead.get(design),
                                    user_model=model)

    if difference is not None:
        # each panel names its metric as the other figures do (report latency, not its id)
        rows = [(metric_label(n, d), d["difference"], *(d["ci95"] or [None, None]))
                for n, d in difference.items() if d["difference"] is not None]
        units = {metric_label(n, d): "pp" if in_percent(d) else (d.get("unit") or "")
                 for n, d in difference.items()}
        # a difference the paired method gives no interval is named in the figure's note,
        # with the reason the table's CI method cell gives
        reasons = {metric_label(n, d): ("fewer than 2 users' durations differ between the "
                                         "designs" if why == NO_DURATION_INTERVAL
                                         else why.removeprefix("none: "))
                   for n, d in difference.items() if (why := no_interval_reason(d))}
        # a difference every user shared is marked in the figure as in the table, and the
        # figure says what that means too (it is printed on its own)
        alike = figure_marks({metric_label(n, d): [d] for n, d in difference.items()
                              if d["difference"] is not None})
        compared = ((plots.comparison_figure(rows, figures / "comparison.png", units,
                                             no_interval=reasons, **alike),)
                    if rows else ())
        headers: tuple[str, ...] = ("metric", names["A"], names["B"], "difference", "95 % CI",
                                    "CI method", "verdict")
        sections.append(Section(f"{names['B']} compared with {names['A']}", paragraphs=(
            (f"Differences {names['B']} − {names['A']} per metric on the same simulated users "
            "(paired); 'differs' marks intervals that exclude zero."
            + _no_interval_words(difference)),
            *filter(None, [no_spread_note(difference.values())])),
            tables=(Table(headers, tuple(comparison_rows(difference))),),
            images=compared,
            captions=("Paired differences with 95 % CIs, each on its own scale",)
            if compared else ()))
        if population and population.get("subgroups"):
            headers, rows = subgroup_comparison_rows(population)
            marked_note = no_spread_note(d for g in population["subgroups"].values()
                                         for d in (g.get("difference") or {}).values())
            sections.append(Section(f"{names['B']} compared with {names['A']}, by subgroup",
                                    paragraphs=(
                ("The same paired differences within each subgroup: a design change can "
                 "help one kind of user and not another. * marks intervals that exclude "
                 "zero."), *filter(None, [marked_note])), tables=(Table(headers, tuple(rows),
                                           "Paired differences B − A per subgroup "
                                           "[95 % CI]"),)))

    if plan.get("input_uncertainty"):      # the fitted model's parameter draws
        from opspec.evaluation.input_uncertainty import report_section

        sections.append(report_section(store, given_a, (summaries.get("B") or {}).get(
            "difference") if "B" in designs else None))

    if failures:
        from opspec.evaluation.failures import advice

        todo = advice(failures)
        sections.append(Section("Failed replications", paragraphs=(
            f"They are left out of every number above. {todo[:1].upper()}{todo[1:]}.",),
            tables=(Table(("specification", "user", "error"),
                          tuple((names.get(d, d), str(u), e) for d, u, e in failures[:200])),
                    )))

    sections.append(_methods_section([per_design, summaries], sections))

    return f"Evaluation of {Path(specs.get(designs[0], 'spec')).name}", sections
