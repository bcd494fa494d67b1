"""The report's section "Who the simulated users are": the user model's parameters per
activity with their sources, and for a population what its file declares (who differs, how,
correlated how) and who was drawn (users per subgroup, the parameters drawn, a figure of
them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from opspec.evaluation.describe import (
    correlation_rows,
    population_notes,
    user_model_notes,
    user_model_rows,
    variation_rows,
)
from opspec.evaluation.store import ResultStore
from opspec.evaluation.tables import (
    PARAMETER_HEADERS,
    SUBGROUP_HEADERS,
    parameter_rows,
    subgroup_rows,
)

__all__ = ["user_model_as_run", "user_model_section"]


def user_model_as_run(store: ResultStore, plan: Mapping[str, Any]) -> Any:
    """The run's user model (``plan``'s) as its file is now, when that is the file the run
    used; None without one, when it cannot be loaded, or when it has changed since (what the
    report then says of the model must not rest on it)."""
    ref = plan.get("user_model")
    if not ref:
        return None
    try:
        from opspec.evaluation.plan import file_digest
        from opspec.usermodels.loader import load_user_model

        stored = store.get("user_model_sha256")
        if stored and Path(str(ref)).is_file() and file_digest(str(ref)) != stored:
            return None
        return load_user_model(str(ref))
    except Exception:  # noqa: BLE001 - the report says less, as user_model_section does
        return None


def _drawn_values(store: ResultStore, design: str, names: Sequence[str]
                  ) -> dict[str, dict[str, list[float]]]:
    """Per drawn parameter, per subgroup (or all users), the values drawn for the users."""
    rows = store.query(
        "SELECT p.parameter, g.subgroup, p.value FROM person_parameter p JOIN person g ON "
        "g.design = p.design AND g.user = p.user WHERE p.design = ? ORDER BY p.rowid",
        (design,))
    out: dict[str, dict[str, list[float]]] = {n: {} for n in names}
    for name, group, value in rows:
        out.setdefault(str(name), {}).setdefault(str(group or "all users"), []).append(
            float(value))
    return out


def _population_part(store: ResultStore, model: Any, population: Mapping[str, Any] | None,
                     figures: Path, design: str) -> tuple[list[str], list[Any], list[Path],
                                                          list[str], list[str]]:
    """Paragraphs, tables, figures, captions and notes on the population: what the file
    declares, and who was drawn."""
    from opspec.evaluation import plots
    from opspec.evaluation.html import Table

    declared = model.population
    paragraphs = [("The simulated users are a population: each user's subgroup and some of "
                  "their parameters are drawn once per user, as declared below; the tables "
                  "after it show who was drawn.")]
    tables = [Table(("subgroup", "share", "parameter", "per-user distribution", "mean", "sd",
                     "5–95 %", "source"), tuple(variation_rows(declared)),
                    "Parameters that differ by person, as the user-model file declares them")]
    correlations = correlation_rows(declared)
    if correlations:
        tables.append(Table(("subgroup", "parameters", "stated", "copula r", "source"),
                            tuple(correlations),
                            "Correlations between a person's parameters (Gaussian copula)"))
    images: list[Path] = []
    captions: list[str] = []
    if population:
        if population.get("subgroups"):
            test = population.get("shares_test")
            tables.append(Table(SUBGROUP_HEADERS, tuple(subgroup_rows(population)),
                                "Users drawn per subgroup: realised share with its exact 95 % "
                                "interval, and the share asked for"
                                + (f" (chi-square test p = {test['p_value']:.3g})"
                                   if test else "")))
        tables.append(Table(PARAMETER_HEADERS, tuple(parameter_rows(population)),
                            "Parameters drawn per user (each user's value is stored with "
                            "their replication: person_parameter in results.sqlite)"))
        values = _drawn_values(store, design, list(population.get("parameters") or {}))
        order = list(population.get("subgroups") or {})      # as the file declares them
        values = {n: dict(sorted(v.items(), key=lambda kv: order.index(kv[0])
                                 if kv[0] in order else len(order))) for n, v in values.items()}
        images.append(plots.parameters_figure(values, figures / "population-parameters.png"))
        captions.append("The parameters drawn for the simulated users, one panel per "
                        "parameter, by subgroup (outline histograms, share of each "
                        "subgroup's users)")
    return paragraphs, tables, images, captions, population_notes(declared)


def user_model_section(store: ResultStore, plan: Mapping[str, Any], figures: Path,
                       population: Mapping[str, Any] | None = None) -> Any:
    """The section on the run's user model (``plan``'s), with who was drawn when it is a
    population (``population``: :func:`.summary.summarise_population`)."""
    from opspec.evaluation.html import Section, Table

    ref = plan.get("user_model")
    if not ref:
        return Section("Who the simulated users are", paragraphs=(
            "No user model: the spec has no user lane, so no person is simulated.",))
    try:
        from opspec.evaluation.plan import file_digest
        from opspec.usermodels.loader import load_user_model

        stored = store.get("user_model_sha256")
        changed = bool(stored and Path(str(ref)).is_file()
                       and file_digest(str(ref)) != stored)
        model = load_user_model(str(ref))
    except Exception as error:  # noqa: BLE001 - say why, keep the rest of the report
        return Section("Who the simulated users are", paragraphs=(
            f"User model {ref}: its parameters cannot be listed here ({error}).",))
    paragraphs = [(f"User model {model.name} ({ref}). Every activity of the user's lane is "
                  "performed with these parameters; durations are in seconds of simulated "
                  "time.")]
    if changed:
        paragraphs.append(f"Warning: {ref} has changed since the run started; the table "
                          "shows the file as it is now, not necessarily what the run used.")
    tables = [Table(("activity", "duration", "errors", "source"),
                    tuple(user_model_rows(model)),
                    "User-model parameters per activity"
                    + (" (the typical user)" if model.population is not None else ""))]
    notes = user_model_notes(model)
    images: list[Path] = []
    captions: list[str] = []
    if model.population is not None:
        more, extra, images, captions, more_notes = _population_part(
            store, model, population, figures, str((plan.get("designs") or [{}])[0].get(
                "label", "A")))
        paragraphs += more
        tables += extra
        notes += more_notes
    return Section("Who the simulated users are", paragraphs=tuple(paragraphs),
                   tables=tuple(tables), images=tuple(images), captions=tuple(captions),
                   items=tuple(notes))

