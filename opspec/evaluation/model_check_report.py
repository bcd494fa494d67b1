"""The short HTML report of ``opspec model-check --report DIR``: the verdict, the table of
items, a QQ plot per activity (observed against predicted quantiles, with the band 95 % of
simulated groups of the same people fall in) and an interval per metric (the people's values
and their mean against the model's predictive intervals). One self-contained file: the
figures are SVG written inline by matplotlib, all text escaped, no dates (the same check
gives the same bytes)."""

from __future__ import annotations

import html
import io
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError

__all__ = ["write_report"]

_STYLE = """body{font-family:system-ui,sans-serif;max-width:60rem;margin:2rem auto;padding:0 1rem;
color:#111;background:#fff}table{border-collapse:collapse;width:100%;font-size:.9rem}
th,td{border:1px solid #999;padding:.3rem .5rem;text-align:left;vertical-align:top}
.misfit{font-weight:bold}.figs{display:flex;flex-wrap:wrap;gap:1rem}
figure{margin:0;max-width:28rem}figcaption{font-size:.85rem}svg{max-width:100%;height:auto}"""


def _svg(figure: Any) -> str:
    import matplotlib.pyplot as plt

    buffer = io.StringIO()
    figure.savefig(buffer, format="svg", metadata={"Date": None})
    plt.close(figure)
    text = buffer.getvalue()
    return text[text.index("<svg"):]


def _qq(item: Any) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = item.figure
    fig, ax = plt.subplots(figsize=(4.2, 4.0))
    ax.fill_between(f["predicted"], f["low"], f["high"], color="#bbb",
                    label="95 % of simulated groups")
    ax.plot(f["predicted"], f["observed"], "o", ms=3, color="#b00" if item.misfit else "#036",
            label="these people")
    top = max(max(f["predicted"]), max(f["observed"]), max(f["high"]))
    ax.plot([0, top], [0, top], "k--", lw=0.8, label="observed = predicted")
    ax.set_xlabel("predicted quantile (s)")
    ax.set_ylabel("observed quantile (s)")
    ax.set_title(item.name, fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return _svg(fig)


def _interval(item: Any) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = item.figure
    fig, ax = plt.subplots(figsize=(4.2, 1.9))
    ax.plot([f["person_low"], f["person_high"]], [1, 1], lw=6, color="#ccc",
            label="95 % of single people")
    ax.plot([f["groups_low"], f["groups_high"]], [0, 0], lw=6, color="#888",
            label=f"95 % of group means (n = {item.persons})")
    ax.plot(f["people"], [1] * len(f["people"]), "|", ms=14, color="#036",
            label="each person")
    ax.plot([item.observed["value"]], [0], "D", color="#b00" if item.misfit else "#036",
            label="their mean")
    ax.set_yticks([0, 1], ["mean", "people"])
    ax.set_ylim(-0.8, 1.8)
    ax.set_title(item.name + (f" ({item.unit})" if item.unit else "")
                 + (" (rate per offer)" if item.kind != "metric" else ""), fontsize=10)
    ax.legend(fontsize=6, loc="upper center", ncol=2, bbox_to_anchor=(0.5, -0.25))
    fig.tight_layout()
    return _svg(fig)


def write_report(report: Any, directory: str | Path, *, title: str) -> Path:
    """Write ``DIRECTORY/model-check.html`` for a :class:`~opspec.usermodels.checking.
    CheckReport`; returns its path."""
    e = html.escape
    misfit_row = '<tr class="misfit">'
    rows = "\n".join(
        f"{misfit_row if i.misfit else '<tr>'}<td>{'MISFIT' if i.misfit else 'fits'}"
        f"</td><td>{e(i.name)}</td><td>{e(i.test)}</td><td>{i.statistic:.4g}</td>"
        f"<td>{i.p:.3g}</td><td>{i.p_holm:.3g}</td><td>{e(i.comparison())}"
        "</td></tr>" for i in report.items)
    figures = []
    for item in report.items:
        if item.kind == "duration" and item.figure.get("observed"):
            figures.append((item, _qq(item), "QQ plot: observed against predicted quantiles"))
        elif item.kind == "metric" or "person_low" in item.figure:
            figures.append((item, _interval(item), "the people's values and the model's "
                            "predictive intervals"))
    figs = "\n".join(f"<figure>{svg}<figcaption>{e(item.name)}: {e(caption)}</figcaption>"
                     "</figure>" for item, svg, caption in figures)
    verdict = report.lines()[-1]
    notes = "".join(f"<li>{e(n)}</li>" for n in report.notes)
    text = (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width\"><title>{e(title)}</title>"
            f"<style>{_STYLE}</style></head><body><h1>{e(title)}</h1>"
            f"<p><strong>{e(verdict)}</strong></p>"
            f"<p>{e(report.method())}. {report.persons} person(s), {report.sessions} "
            f"session(s); {report.replicates} simulated groups; parameter uncertainty: "
            f"{e(report.uncertainty)}; seed {report.seed}.</p>"
            "<h2>Items</h2><table><caption>each item with its test, p-value and "
            "Holm-adjusted p-value</caption><thead><tr><th scope=\"col\">verdict</th>"
            "<th scope=\"col\">item</th><th scope=\"col\">test</th><th scope=\"col\">"
            "statistic</th><th scope=\"col\">p</th><th scope=\"col\">Holm p</th>"
            f"<th scope=\"col\">observed against predicted</th></tr></thead><tbody>{rows}"
            f"</tbody></table>" + (f"<h2>Notes</h2><ul>{notes}</ul>" if notes else "")
            + f"<h2>Figures</h2><div class=\"figs\">{figs}</div></body></html>\n")
    out = Path(directory)
    try:
        out.mkdir(parents=True, exist_ok=True)
        path = out / "model-check.html"
        path.write_text(text, encoding="utf-8")
    except OSError as error:
        raise EvaluationError(f"cannot write the report in {out}: "
                              f"{error.strerror or error}",
                              hint="choose a writable folder with --report") from None
    return path
