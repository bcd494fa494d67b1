"""The log `opspec evaluate --export xes` writes is named after the spec (the XES Concept
extension: a log's ``concept:name`` is the name of the process executed, which ProM, Disco
and pm4py list a log by; it was "opspec traces" for every spec, while docs/xes-export.md
showed the spec's name), and every log attribute it writes is documented there (``spec``,
``seed`` and ``case_notion`` were written and not described)."""

from __future__ import annotations

import re
from pathlib import Path

from evaluate_without_report import without_report
from lxml import etree

from opspec.cli import main
from opspec.evaluation.exporters import XES_NAMESPACE

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
DOC = ROOT / "docs" / "xes-export.md"


def _log_attributes(path: Path) -> dict[str, str]:
    log = etree.parse(str(path)).getroot()
    return {child.get("key"): child.get("value") for child in log
            if child.get("key") is not None and child.tag != f"{{{XES_NAMESPACE}}}trace"}


def _export(tmp_path: Path, *more: str, formats: str = "xes") -> dict[str, str]:
    out = tmp_path / "run"
    with without_report():
        assert main(["evaluate", str(SPEC), "--users", "1", "--days", "1", "--seed", "7",
                     "--workers", "1", "--user-model", str(USERS), "--quiet", "--export",
                     formats, "--case", "user", "--out", str(out), *more]) == 0
    return _log_attributes(out / "traces.xes")


def test_the_log_is_named_after_the_spec_and_documented(tmp_path, capsys):
    log = _export(tmp_path)
    capsys.readouterr()
    assert log["concept:name"] == "Smart medication dispenser and its user"
    assert log["spec"] == str(SPEC) and log["seed"] == "7" and log["case_notion"] == "user"
    # docs/xes-export.md's table of the log's attributes names every one written
    documented = set(re.findall(r"^\| `([^`]+)` \|", DOC.read_text(encoding="utf-8"), re.MULTILINE))
    assert set(log) <= documented, set(log) - documented
    assert f'<string key="concept:name" value="{log["concept:name"]}"/>' in DOC.read_text(
        encoding="utf-8")


def test_a_comparison_of_two_specs_names_both(tmp_path, capsys):
    other = tmp_path / "quiet.xpdl"
    text = SPEC.read_text(encoding="utf-8")
    old = 'Name="Smart medication dispenser and its user"'
    assert text.count(old) == 1
    other.write_text(text.replace(old, 'Name="Quieter dispenser"'), encoding="utf-8")
    log = _export(tmp_path, "--compare", str(other))
    capsys.readouterr()
    assert log["concept:name"] == ("Smart medication dispenser and its user compared with "
                                   "Quieter dispenser")


def test_the_jsonl_header_names_the_run_in_the_xes_log_s_words(tmp_path, capsys):
    """Both exports of one evaluation say which spec, seed and case notion they hold, under
    the same keys (the JSON Lines header said ``"case notion"``, with a space, where the XES
    log says ``case_notion``), and docs/trace-format.md names the header's keys."""
    import json

    log = _export(tmp_path, formats="xes,jsonl")
    capsys.readouterr()
    with (tmp_path / "run" / "traces.jsonl").open(encoding="utf-8") as handle:
        head = json.loads(handle.readline())
    assert head["cases"] is True
    for key in ("spec", "seed", "case_notion"):
        assert str(head[key]) == log[key], key
    documented = (ROOT / "docs" / "trace-format.md").read_text(encoding="utf-8")
    for key in head:
        assert f"`{key}`" in documented or f'"{key}"' in documented, key
