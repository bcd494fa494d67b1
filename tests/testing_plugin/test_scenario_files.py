"""Scenario files (*.scenario.toml) collected as tests; failures and bad files explained."""

from __future__ import annotations

import pytest


def _literal(pattern: str) -> str:
    """An fnmatch pattern where '[' is literal ('*' and '?' keep their meaning)."""
    return pattern.replace("[", "[[]")

GOOD = '''
spec = "specs/dispenser.xpdl"

[[scenario]]
name = "prompt user"
given = { script = [["after trg_2 90s", "press_report"]], until = "09:00" }
then = ["doses_taken == 1", "report_latency_s.mean == 90"]

[[scenario]]
name = "silent user"
given.script = [["never", "press_report"]]
given.until = "09:00"
then = ["alarms == 3", "never activity dispense", "caregiver_notified == 1"]
'''


def test_each_scenario_is_a_test_named_after_it(project: pytest.Pytester) -> None:
    (project.path / "dispenser.scenario.toml").write_text(GOOD)
    result = project.runpytest("-v")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*dispenser.scenario.toml::prompt user PASSED*",
                                 "*dispenser.scenario.toml::silent user PASSED*"])


def test_a_failing_scenario_shows_the_expectation_the_values_and_a_trace_slice(
        project: pytest.Pytester) -> None:
    (project.path / "dispenser.scenario.toml").write_text(GOOD.replace(
        '"never activity dispense"', '"eventually activity dispense"').replace(
        '"alarms == 3"', '"alarms == 1"'))
    result = project.runpytest()
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines([_literal(line) for line in [
        "*dispenser.scenario.toml:13: scenario[1].then[0]: expected alarms == 1",
        "  but alarms = 3",
        "*d1 08:10:00*sound_alarm",
        "*dispenser.scenario.toml:13: scenario[1].then[1]: expected eventually activity dispense",
        "  but activity dispense never happened (the run went to d1 09:00:00)",
        "  the trace ends with:",
        "(seed *; 1 replication(s))"]])
    assert "Traceback" not in result.stdout.str()
    assert "opspec/testing" not in result.stdout.str()


def test_a_statistical_scenario_with_too_few_users_says_how_many(
        project: pytest.Pytester) -> None:
    (project.path / "stats.scenario.toml").write_text('''
spec = "specs/dispenser.xpdl"
[[scenario]]
name = "few users"
given = { user_model = "specs/dispenser.users.toml", users = 5 }
then = ["rate doses_taken/doses_due >= 0.99 with 95% confidence"]
''')
    result = project.runpytest()
    result.stdout.fnmatch_lines(["*too few replications to decide: about * replications*"])


def test_the_seed_option_reaches_scenarios(project: pytest.Pytester) -> None:
    (project.path / "seeded.scenario.toml").write_text('''
spec = "specs/dispenser.xpdl"
[[scenario]]
name = "latency"
given = { user_model = "specs/dispenser.users.toml", users = 2 }
then = ["report_latency_s.mean == 0"]
''')
    def latency(*args: str) -> str:
        out = project.runpytest(*args).stdout.str()
        return next(line for line in out.splitlines() if "but report_latency_s.mean" in line)

    assert latency("--opspec-seed=3") == latency("--opspec-seed=3")
    assert latency("--opspec-seed=3") != latency("--opspec-seed=4")


BAD = {
    "unknown-top-key": ('spec = "specs/dispenser.xpdl"\nspecs = 1\n', "specs: unknown key 'specs'"),
    "missing-spec": ('[[scenario]]\nname = "x"\nthen = ["alarms == 1"]\n',
                     "spec: the file needs spec ="),
    "spec-not-found": ('spec = "nope.xpdl"\n[[scenario]]\nname = "x"\nthen = ["alarms == 1"]\n',
                       "spec: spec 'nope.xpdl' not found"),
    "no-scenarios": ('spec = "specs/dispenser.xpdl"\n', "scenario: no [[scenario]] tables"),
    "unreadable-then": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                        'then = ["alarms are many"]\n'),
                        "scenario[0].then[0]: cannot read the expectation 'alarms are many'"),
    "unknown-metric": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                       'then = ["doses == 1"]\n'),
                       ("scenario[0].then[0]: 'doses == 1' names metric 'doses', which the spec "
                       "does not have (the spec's metric names are: doses_due*")),
    "unknown-given-key": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                          'given = { user = 3 }\nthen = ["alarms == 1"]\n'),
                          "scenario[0].given.user: unknown key 'user'"),
    "bad-script-step": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                        'given = { script = [["soon", "press_report"]] }\nthen = ["alarms == 1"]\n'),
                        "scenario[0].given.script[0]: cannot read the time 'soon'*"),
    "script-unknown-activity": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                                'given = { script = [["never", "report"]] }\n'
                                'then = ["alarms == 1"]\n'),
                                ("scenario[0].given.script[0]: the script names activity "
                                 "'report'*")),
    "script-step-on-a-device-activity": (
        ('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
         'given = { script = [["10s", "dispense"]] }\nthen = ["alarms == 1"]\n'),
        ("scenario[0].given.script[0]: the script's step 'complete dispense' names activity "
         "'dispense', which is never offered to the user (lane 'device' performs it*")),
    "negative-users": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                       'given = { users = 0 }\nthen = ["alarms == 1"]\n'),
                       "scenario[0].given.users: users must be a whole number >= 1, not 0"),
    "not-toml": ('spec = \n', "not valid TOML*"),
    "twice-the-same-name": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                            'then = ["alarms == 1"]\n[[scenario]]\nname = "x"\n'
                            'then = ["alarms == 1"]\n'),
                            "scenario[1].name: scenario name 'x' is used twice"),
    "unknown-user-model": (('spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
                           'given = { user_model = "nobody" }\nthen = ["alarms == 1"]\n'),
                           "scenario[0].given.user_model: *nobody*"),
}


#: the line each mistake of BAD is written on (none: a key that is not written at all); a key
#: inside an inline table (given = { users = 0 }) is placed at the line of that table
LINES = {"unknown-top-key": 2, "spec-not-found": 1, "unreadable-then": 4, "unknown-metric": 4,
         "unknown-given-key": 4, "bad-script-step": 4, "script-unknown-activity": 4,
         "script-step-on-a-device-activity": 4, "negative-users": 4,
         "twice-the-same-name": 6, "unknown-user-model": 4}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_a_bad_scenario_file_is_a_collection_error_naming_the_file_line_and_key(
        project: pytest.Pytester, case: str) -> None:
    text, message = BAD[case]
    (project.path / "bad.scenario.toml").write_text(text)
    result = project.runpytest()
    result.assert_outcomes(errors=1)
    line = f":{LINES[case]}" if case in LINES else ""
    result.stdout.fnmatch_lines([_literal(
        f"bad scenario file: bad.scenario.toml{line}: {message}*")])
    assert "Traceback" not in result.stdout.str()


def test_a_script_file_s_bad_step_is_placed_at_its_own_line(project: pytest.Pytester) -> None:
    # the step is written in the script file, so that is where an editor must jump; the
    # scenario that uses the script is named beside it (it was placed at the scenario's key)
    (project.path / "late.toml").write_text(
        'otherwise = "complete"\nsteps = [\n  ["after trg_2 60s", "press_report"],\n'
        '  ["10s", "dispense"],\n]\n')
    (project.path / "bad.scenario.toml").write_text(
        'spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
        'given = { script = "late.toml" }\nthen = ["alarms == 1"]\n')
    result = project.runpytest()
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines([_literal(
        "bad scenario file: late.toml:4: steps[1]: the script's step 'complete dispense' "
        "names activity 'dispense'") + "*"
        + _literal("(scenario 'x', bad.scenario.toml:4: scenario[0].given.script)") + "*"])
