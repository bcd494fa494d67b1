"""``--report-template`` is code: a template that came with a spec (in its folder) is refused
unless the user says so, and every template runs sandboxed (it cannot reach Python's
internals)."""

from __future__ import annotations

import shutil
from pathlib import Path

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
ESCAPE = "{{ ''.__class__.__mro__[1].__subclasses__() }}"


def test_a_template_in_the_specs_folder_is_refused_unless_trusted(tmp_path, capsys) -> None:
    shutil.copy(SPEC, tmp_path)
    shutil.copy(SPEC.with_name("medication_dispenser.users.toml"), tmp_path)
    template = tmp_path / "templates" / "report.html.j2"
    template.parent.mkdir()
    template.write_text("<html>{{ title }}</html>", encoding="utf-8")
    args = ["evaluate", str(tmp_path / SPEC.name), "--users", "1", "--days", "1",
            "--workers", "1", "--quiet", "--report-template", str(template)]
    assert main([*args, "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err
    assert "a template is code" in err and "--trust-spec-template" in err
    assert not (tmp_path / "a").exists()
    assert main([*args, "--out", str(tmp_path / "b"), "--trust-spec-template"]) == 0
    assert (tmp_path / "b" / "report.html").read_text(encoding="utf-8").startswith("<html>")


def test_a_template_cannot_reach_pythons_internals(tmp_path, capsys) -> None:
    from opspec.errors import EvaluationError
    from opspec.evaluation.html import render_html

    template = tmp_path / "escape.j2"
    template.write_text(ESCAPE, encoding="utf-8")
    try:
        render_html("t", [], template)
    except EvaluationError as error:
        assert "the report template fails" in str(error) and "unsafe" in str(error)
    else:
        raise AssertionError("the sandbox let the template reach object.__subclasses__")


def test_a_template_prepared_ahead_and_then_changed_is_rendered_as_it_is_now(
        tmp_path) -> None:
    # evaluate --workers W reads and compiles the template while its workers run; the
    # report must still show the template as it is when the report is written
    from opspec.evaluation.html import prepare_template, render_html

    template = tmp_path / "report.j2"
    template.write_text("<p>first {{ title }}</p>", encoding="utf-8")
    prepare_template(template)
    template.write_text("<p>second {{ title }}</p>", encoding="utf-8")
    assert render_html("dose", [], template) == "<p>second dose</p>"


def test_a_broken_template_prepared_ahead_still_fails_the_report_at_its_line(
        tmp_path) -> None:
    from opspec.errors import EvaluationError
    from opspec.evaluation.html import render_html
    from opspec.evaluation.report import prepare_report

    template = tmp_path / "broken.j2"
    template.write_text("<html>\n{{ title }\n</html>", encoding="utf-8")
    prepare_report(template)                    # while the workers run: says nothing
    try:
        render_html("t", [], template)
    except EvaluationError as error:
        assert f"{template}:2: the report template fails" in str(error)
    else:
        raise AssertionError("a template that does not compile was rendered")
