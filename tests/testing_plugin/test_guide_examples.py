"""Every Python and TOML example of docs/spec-testing.md runs, as a device team would use it:
in a test file beside the dispenser spec (``specs/tests/``), and does what the guide says.

The guide's examples are test modules or fragments of one; each fragment runs inside the
harness named by its first line (:data:`HARNESSES`). An example added to the guide without a
harness fails :func:`test_every_example_of_the_guide_has_a_harness`, so none goes unrun.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

from .conftest import DISPENSER, USERS

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "spec-testing.md"
FENCE = re.compile(r"^```(python|toml)\n(.*?)^```", re.MULTILINE | re.DOTALL)

#: a fragment run in a test of its own: the fixtures, a one-user day of a prompt user as
#: ``result``, and the names the guide's fragments use
IN_A_TEST = '''
from opspec.testing import check, holds, min_gap

SPEC = "../medication_dispenser.xpdl"
USERS = "../medication_dispenser.users.toml"


def test_example(spec, simulate):
    result = simulate(spec, script=[("each after trg_2 45s", "press_report")], days=1)
{block}
'''

#: how each example runs, by its first line; "{block}" is the example's text
HARNESSES = {
    "# specs/tests/test_medication_dispenser.py": "{block}",
    '@pytest.fixture(scope="module")': '''
import pytest
from opspec.testing import expect, simulator_for

SPEC = "../medication_dispenser.xpdl"
USERS = "../medication_dispenser.users.toml"

{block}

def test_shared_run(reference_users):
    assert reference_users.replications == 600
    expect(reference_users, "rate doses_taken/doses_due >= 0.99 with 95% confidence")
''',
    '[("after trg_2 90s", "press_report")]': "scripts",        # see test_the_scripts_...
    'otherwise = "complete"': "script file",                    # see test_the_script_file_...
    'spec = "../medication_dispenser.xpdl"': "scenario file",   # see test_the_scenario_file_...
    'assert holds("run.jsonl"': IN_A_TEST,
    "from opspec.testing import check, count, happens_before,": IN_A_TEST,
    "from opspec.testing import assert_rate_sequential": "{block}",
    "from opspec.testing import assert_no_violations, min_gap": IN_A_TEST,
}

#: what the guide's comments say of each script of its list (one per line), as metrics of a
#: user who follows it through the 08:00 dose
SCRIPT_CLAIMS = [
    {"doses_taken": 1, "report_latency_s": 90},                         # reports 90 s after
    {"alarms": 3, "doses_missed": 1, "caregiver_notified": 1},         # never reports
    {"doses_taken": 1, "report_latency_s": 70},                         # 70 s, one mistake
    {"doses_taken": 1, "report_latency_s": 290, "alarms": 1},           # just before the 2nd
    {"doses_taken": 1, "report_latency_s": 180},                        # a report from elsewhere
]


def _examples() -> list[tuple[str, str]]:
    """(language, text) of every Python and TOML block of the guide, in order."""
    return [(m[1], m[2]) for m in FENCE.finditer(GUIDE.read_text(encoding="utf-8"))]


def _harness(text: str) -> str | None:
    first = text.splitlines()[0]
    found = [h for key, h in HARNESSES.items() if first.startswith(key)]
    return found[0] if len(found) == 1 else None


def _example(key: str) -> str:
    (text,) = [t for _, t in _examples() if t.startswith(key)]
    return text


def test_every_example_of_the_guide_has_a_harness() -> None:
    examples = _examples()
    assert len(examples) >= len(HARNESSES)
    for _, text in examples:
        assert _harness(text) is not None, (
            f"docs/spec-testing.md: no harness for the example {text.splitlines()[0]!r}")


@pytest.fixture
def beside_the_spec(pytester: pytest.Pytester) -> Path:
    """A project with the dispenser spec and its users in specs/; returns specs/tests/."""
    specs = pytester.path / "specs"
    (specs / "tests").mkdir(parents=True)
    (specs / "medication_dispenser.xpdl").write_bytes(DISPENSER.read_bytes())
    (specs / "medication_dispenser.users.toml").write_bytes(USERS.read_bytes())
    return specs / "tests"


def _runnable() -> list[tuple[str, str]]:
    out = []
    for _, text in _examples():
        harness = _harness(text)
        if harness is not None and "{block}" in harness:
            out.append((text.splitlines()[0], harness))
    return out


@pytest.mark.parametrize(("first", "harness"), _runnable(), ids=[f for f, _ in _runnable()])
def test_each_python_example_passes_beside_the_spec(pytester: pytest.Pytester,
                                                     beside_the_spec: Path, first: str,
                                                     harness: str) -> None:
    text = _example(first)
    block = textwrap.indent(text, "    ") if harness is IN_A_TEST else text
    (beside_the_spec / "test_example.py").write_text(harness.replace("{block}", block),
                                                     encoding="utf-8")
    if "run.jsonl" in text:      # the stored trace the example reads: a prompt user's day
        (pytester.path / "prompt.toml").write_text(
            'steps = [{ when = "each after trg_2 45s", do = "press_report" }]\n')
        subprocess.run([sys.executable, "-m", "opspec", "run",
                        "specs/medication_dispenser.xpdl", "--script", "prompt.toml",
                        "--trace", "run.jsonl"], cwd=pytester.path, check=True,
                       capture_output=True)
    result = pytester.runpytest(str(beside_the_spec / "test_example.py"))
    outcomes = result.parseoutcomes()
    assert outcomes.get("passed", 0) >= 1 and set(outcomes) <= {"passed"}, result.stdout.str()


def test_the_scripts_of_the_guides_list_do_what_their_comments_say(
        pytester: pytest.Pytester, beside_the_spec: Path) -> None:
    lines = _example('[("after trg_2 90s", "press_report")]').splitlines()
    scripts = [ast.literal_eval(line.split("#")[0].strip()) for line in lines]
    assert len(scripts) == len(SCRIPT_CLAIMS)
    (beside_the_spec / "test_scripts.py").write_text(f'''
import pytest

SCRIPTS = {scripts!r}
CLAIMS = {SCRIPT_CLAIMS!r}


@pytest.mark.parametrize("n", range(len(SCRIPTS)))
def test_script(simulate, n):
    result = simulate("../medication_dispenser.xpdl", script=SCRIPTS[n], until=9 * 3600)
    assert {{name: result.value(name) for name in CLAIMS[n]}} == CLAIMS[n]
''', encoding="utf-8")
    pytester.runpytest(str(beside_the_spec)).assert_outcomes(passed=len(scripts))


def test_the_script_file_of_the_guide_is_read_and_followed(pytester: pytest.Pytester,
                                                           beside_the_spec: Path) -> None:
    (beside_the_spec / "late.toml").write_text(_example('otherwise = "complete"'))
    (beside_the_spec / "test_late.py").write_text('''
def test_late(simulate):
    result = simulate("../medication_dispenser.xpdl", script="late.toml", until=9 * 3600)
    assert result.value("report_latency_s") == 120 and result.value("doses_taken") == 1
''', encoding="utf-8")
    pytester.runpytest(str(beside_the_spec)).assert_outcomes(passed=1)


def test_the_scenario_file_of_the_guide_passes(pytester: pytest.Pytester,
                                               beside_the_spec: Path) -> None:
    text = _example('spec = "../medication_dispenser.xpdl"')
    (beside_the_spec / "dispenser.scenario.toml").write_text(text, encoding="utf-8")
    result = pytester.runpytest(str(beside_the_spec))
    result.assert_outcomes(passed=text.count("[[scenario]]"))


# ---------------------------------------------------------------- the failures the guide shows
PLAIN = re.compile(r"^```\n(expected .*?)^```", re.MULTILINE | re.DOTALL)
PROMPT_EACH = [("each after trg_2 45s", "press_report")]


def _failure(claim: Callable[[], object]) -> str:
    """The message of the AssertionError ``claim`` raises, without its seed line (the guide
    leaves it out)."""
    with pytest.raises(AssertionError) as failed:
        claim()
    return re.sub(r"\n+\(seed \d+.*\)$", "", str(failed.value)) + "\n"


def _shown_failures(dispenser: object) -> dict[str, Callable[[], object]]:
    """The run and the claim behind each failure the guide shows, by its first line."""
    from opspec.testing import assert_rate, check, expect, simulate, within

    def run(**given: object) -> object:
        return simulate(dispenser, **given)  # type: ignore[arg-type]

    return {
        "expected rate doses_taken/doses_due >= 0.99 with 95% confidence": lambda: expect(
            run(users=10, script=PROMPT_EACH),
            "rate doses_taken/doses_due >= 0.99 with 95% confidence"),
        "expected never activity notify_caregiver": lambda: expect(
            run(script=[("never", "press_report")], days=3), "never activity notify_caregiver"),
        "expected within(sound_alarm, press_report, 60 s)": lambda: check(
            run(script=[("after trg_2 90s", "press_report")], until=9 * 3600),
            within("sound_alarm", "press_report", 60)),
        "expected rate taken_rate >= 0.99 with 95% confidence": lambda: assert_rate(
            run(users=3, script=PROMPT_EACH), "taken_rate", at_least=0.99),
    }


def test_the_failures_the_guide_shows_are_those_of_its_runs() -> None:
    from opspec.engine.compiled import compile_package
    from opspec.testing.simulation import load_spec_file

    shown = PLAIN.findall(GUIDE.read_text(encoding="utf-8"))
    claims = _shown_failures(compile_package(load_spec_file(DISPENSER)))
    assert sorted(text.splitlines()[0] for text in shown) == sorted(claims)
    for text in shown:
        assert _failure(claims[text.splitlines()[0]]) == text
