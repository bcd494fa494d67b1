"""The defaults and thresholds the user documentation states are the program's.

Each test reads the sentence of the page that states a number and the constant or option the
program uses, so that changing one without the other fails here (the commands of the pages
are run by ``test_docs_commands``; a default is often not visible in their output).
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _page(name: str) -> str:
    path = ROOT / "docs" / name if name != "README.md" else ROOT / name
    return " ".join(path.read_text(encoding="utf-8").split())   # lines joined: prose wraps


def _option(command: str, option: str):
    from opspec.cli import _subparsers, build_parser

    parser = _subparsers(build_parser(command))[command]
    return next(a for a in parser._actions if option in a.option_strings)


def test_evaluate_users_default_is_evaluation_mds() -> None:
    from opspec.commands.evaluate_plan import DEFAULT_USERS

    assert f"| `--users N` | simulated users (default {DEFAULT_USERS});" in _page(
        "evaluation.md")


def test_scheduler_timeout_default_is_evaluation_mds() -> None:
    from opspec.evaluation.runner import WORKER_TIMEOUT

    page = _page("evaluation.md")
    assert f"(default {WORKER_TIMEOUT:g} s)" in page
    assert f"`--scheduler-timeout` seconds ({WORKER_TIMEOUT:g})" in page


def test_figures_default_is_evaluation_mds() -> None:
    from opspec.evaluation.figure_files import DPI

    default = _option("evaluate", "--figures").default
    assert f"(default {default}, inlined in the HTML; pdf with SVG twins; png at {DPI} dpi)" in (
        _page("evaluation.md"))


def test_run_defaults_the_tutorial_states() -> None:
    from opspec.run_rules import DAY

    page = _page("tutorial.md")
    assert DAY == 86400.0 and "(the default is one day)" in page
    assert _option("run", "--timeline").default == "brief"
    assert "the default `brief` timeline" in page


def test_run_help_names_the_until_spelling_the_tutorial_uses() -> None:
    """The tutorial runs ``--until 10:00``; ``opspec run --help`` must name that spelling,
    or a reader who looks the option up is told only of seconds and ISO 8601."""
    assert "--until 10:00" in _page("tutorial.md")
    assert "10:00" in _option("run", "--until").help


def test_no_spread_threshold_is_the_one_the_docs_state() -> None:
    from opspec.statistics.no_spread import ALIKE_SHARE, unlike_share_high

    users = next(u for u in range(1, 10_000) if unlike_share_high(u) <= ALIKE_SHARE)
    assert users == 368
    assert "fewer than 368 users all alike" in _page("evaluation.md")
    assert "368 replications at 95 %" in _page("spec-testing.md")
    assert f"{unlike_share_high(3):.1%}".replace("%", " %") == "70.8 %"
    assert "70.8 % at 3 users" in _page("evaluation.md")


@pytest.mark.parametrize(("constant", "sentence"), [
    ("RARE_EVENTS", "A count per user (`doses_missed`) with fewer than {} events in all"),
    ("MODIFIED_WILSON_EVENTS", ("with the hundreds to millions of trials of an evaluation "
                                "opspec stops at {},")),
])
def test_rare_event_thresholds_are_evaluation_mds(constant: str, sentence: str) -> None:
    from opspec.statistics import clustered, proportions

    value = getattr(clustered, constant, None) or getattr(proportions, constant)
    assert sentence.format(value) in _page("evaluation.md")


def test_scenario_days_default_is_the_spec_run_length(tmp_path: Path) -> None:
    """spec-testing.md: with neither days nor until, a scenario runs the spec's
    opspec:RunLength (toy_sumo says 30 min), as ``simulate`` and ``opspec run`` do."""
    from opspec.testing.scenario import load_scenarios, run_scenario

    assert "with neither, the spec's `opspec:RunLength`, else 1 day" in _page(
        "spec-testing.md")
    file = tmp_path / "length.scenario.toml"
    file.write_text(f'spec = "{ROOT / "specs" / "toy_sumo.xpdl"}"\n'
                    '[[scenario]]\nname = "length"\nthen = ["count process sense >= 0"]\n',
                    encoding="utf-8")
    document = load_scenarios(file)
    seen = []
    failures = run_scenario(document.scenarios[0], ROOT / "specs" / "toy_sumo.xpdl", seed=0,
                            seen=seen.append)
    assert failures == [] and seen[0].horizon == 1800.0


def test_equality_tolerance_of_an_expectation_is_spec_testing_mds() -> None:
    from opspec.testing.expectations import _OPS

    assert "(`==` and `!=` allow an error of 1e-9, relative, or absolute near 0)" in _page(
        "spec-testing.md")
    assert _OPS["=="](1e12, 1e12 + 900) and not _OPS["=="](1e12, 1e12 + 1100)   # relative
    assert _OPS["=="](0.0, 9e-10) and not _OPS["=="](0.0, 1.1e-9)              # absolute
    assert _OPS["!="](0.0, 1.1e-9) and not _OPS["!="](0.0, 9e-10)


@pytest.mark.parametrize(("change", "status", "says"), [
    (("[activities.take_pill]", "[activities.take_pil]"), 1,
     "activities.take_pil: error: "),
    (("probability = 0.2,", "probability = 1.2,"), 1,
     "activities.hear_beep.omission.probability: error: "),
    (("[activities.press_taken]", ("[activities.wash_hands]\nduration = 5.0\n\n"
                                   "[activities.press_taken]")), 0,
     "activities.wash_hands: warning: "),
])
def test_what_validate_says_of_a_user_model_typo_is_what_the_tutorial_says(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], change: tuple[str, str],
        status: int, says: str) -> None:
    """tutorial.md, step 6: a misspelt activity and a probability above 1 are errors of
    validate's at the file and key; an activity the spec does not have at all, a warning."""
    from opspec.cli import main

    assert ("a typo in it (a misspelt activity, which leaves the spec's activity without a "
            "duration; a probability above 1) is an error of validate's, at the file and key; "
            "an activity the spec does not have at all is a warning") in _page("tutorial.md")
    step = ROOT / "tests" / "docs" / "tutorial" / "step6"
    (tmp_path / "pill.xpdl").write_bytes((step / "pill.xpdl").read_bytes())
    model = (step / "pill.users.toml").read_text(encoding="utf-8")
    assert change[0] in model
    (tmp_path / "pill.users.toml").write_text(model.replace(change[0], change[1], 1),
                                              encoding="utf-8")
    assert main(["validate", str(tmp_path / "pill.xpdl")]) == status
    assert says in capsys.readouterr().out
