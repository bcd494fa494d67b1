"""A spec file the ``spec`` fixture cannot find: each place looked at is named once, and the
message says what to fix (the test file's ``SPEC =``, or its ``@pytest.mark.spec``).

A test in pytest's rootdir looks next to itself and under the rootdir, the same folder: the
message named it twice (``looked at /x/m.xpdl, /x/m.xpdl``) and did not say what to do.
"""

from __future__ import annotations

import pytest


def _failure(result: pytest.RunResult) -> str:
    rows = [row for row in result.stdout.lines
            if "file not found" in row and not row.startswith("ERROR ")]
    assert len(rows) == 1, result.stdout.str()
    return rows[0]


def test_a_test_in_the_rootdir_names_the_place_looked_at_once(
        pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_m="SPEC = 'm.xpdl'\ndef test_it(spec):\n    pass\n")
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    row = _failure(result)
    place = str(pytester.path / "m.xpdl")
    assert f"m.xpdl: file not found (looked at {place})" in row
    assert row.count(place) == 1


def test_the_message_says_to_fix_spec_in_the_test_file(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_m="SPEC = 'm.xpdl'\ndef test_it(spec):\n    pass\n")
    row = _failure(pytester.runpytest())
    assert "fix SPEC = ... in test_m.py" in row


def test_a_test_below_the_rootdir_names_both_places(pytester: pytest.Pytester) -> None:
    pytester.mkdir("sub")
    (pytester.path / "sub" / "test_n.py").write_text(
        "import pytest\n"
        "@pytest.mark.spec('n.xpdl')\n"
        "def test_it(spec):\n    pass\n")
    row = _failure(pytester.runpytest())
    assert (f"looked at {pytester.path / 'sub' / 'n.xpdl'}, {pytester.path / 'n.xpdl'})"
            in row)
    assert "fix @pytest.mark.spec(...) in test_n.py" in row
