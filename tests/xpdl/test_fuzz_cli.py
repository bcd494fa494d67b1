"""Property-based robustness at the command line: mutated corpus files given to ``opspec
validate``, ``show``, ``compile`` and ``preprocess`` never give an internal error or a
traceback, every error ``validate`` reports has a location with a line, and every message is
one line (issue 2, "Bad input": a clear one-line error naming file:line)."""

from __future__ import annotations

import contextlib
import io
import json
import re
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree
from xml_mutations import mutate_element

from opspec.cli import main

CORPUS = Path("/work/shared/corpus/xpdl")
SAMPLES = sorted(CORPUS.glob("*.xpdl")) if CORPUS.is_dir() else []
SPECS = sorted((Path(__file__).resolve().parents[2] / "specs").glob("*.xpdl"))
DATA = {path.name: path.read_bytes() for path in [*SPECS, *SAMPLES]}

FUZZ = settings(max_examples=12, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# `path:line: severity: message` where the line may be missing only for whole-file problems
# of other files (an unreadable external package); a command's own messages start "opspec".
DIAGNOSTIC = re.compile(r"^.+?:(\d+:)? (error|warning): \S")


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(list(argv))
    return status, out.getvalue(), err.getvalue()


def _mutate(data: bytes, edits: list[tuple[str, float, int]]) -> bytes:
    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        root = None
    raw = bytearray(data)
    for action, where, value in edits:
        if action == "flip" or root is None:
            raw = bytearray(etree.tostring(root)) if root is not None else raw
            root = None
            if raw:
                raw[int(where * len(raw))] = value
            continue
        mutate_element(root, action, where)
    return etree.tostring(root) if root is not None else bytes(raw)


def _check_stderr(err: str) -> None:
    assert "Traceback" not in err and "internal error" not in err, err
    for line in err.splitlines():
        assert line.startswith(("opspec", "  ")) or DIAGNOSTIC.match(line), line


@pytest.mark.skipif(not SAMPLES, reason="shared corpus not present")
@FUZZ
@given(name=st.sampled_from(sorted(DATA)),
       edits=st.lists(st.tuples(st.sampled_from(["delete", "duplicate", "strip", "id", "text",
                                                 "flip"]),
                                st.floats(0, 1, exclude_max=True), st.integers(0, 255)),
                      min_size=1, max_size=5))
def test_commands_on_mutated_specs_give_located_one_line_errors(
    name: str, edits: list[tuple[str, float, int]]
) -> None:
    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder) / name
        spec.write_bytes(_mutate(DATA[name], edits))

        status, out, err = _run("validate", "--json", str(spec))
        assert status in (0, 1), err
        report = json.loads(out)
        for diagnostic in report["diagnostics"]:
            assert diagnostic["code"] != "internal-error", diagnostic
            assert "\n" not in diagnostic["message"] and "\n" not in diagnostic["hint"]
            if diagnostic["severity"] == "error" and diagnostic["path"] == str(spec):
                assert diagnostic["line"] is not None, diagnostic
        _check_stderr(err)

        status, _, err = _run("show", str(spec))
        assert status in (0, 1), err
        _check_stderr(err)
        status, _, err = _run("show", "--format", "dot", str(spec))
        assert status in (0, 1), err
        _check_stderr(err)

        target = Path(folder) / "out.wfs"
        status, _, err = _run("compile", str(spec), "-o", str(target))
        assert status == (0 if report["ok"] else 1), err
        assert target.exists() == report["ok"]
        _check_stderr(err)

        status, _, err = _run("preprocess", str(spec), "-o", str(Path(folder) / "o.xpdl"))
        assert status in (0, 1), err
        if not report["ok"]:
            assert status == 1
        _check_stderr(err)
