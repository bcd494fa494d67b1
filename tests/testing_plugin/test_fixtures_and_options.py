"""The plugin's fixtures and options, seen from a user's test suite (pytester)."""

from __future__ import annotations

import re

import pytest


def test_spec_fixture_loads_the_marked_spec_relative_to_the_rootdir_or_the_test_file(
        project: pytest.Pytester) -> None:
    project.makepyfile(test_specs="""
        import pytest

        @pytest.mark.spec("specs/dispenser.xpdl")
        def test_by_marker(spec):
            assert spec.id == "medication_dispenser"

        def test_by_module_constant(spec):
            assert spec.id == "medication_dispenser"

        SPEC = "specs/dispenser.xpdl"
    """)
    project.mkdir("sub")
    (project.path / "sub" / "test_near.py").write_text(
        "import pytest\n"
        "@pytest.mark.spec('../specs/dispenser.xpdl')\n"
        "def test_near_the_test_file(spec):\n"
        "    assert spec.id == 'medication_dispenser'\n")
    project.runpytest().assert_outcomes(passed=3)


def test_a_test_without_a_spec_is_told_how_to_name_one(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("def test_it(spec):\n    pass\n")
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*needs @pytest.mark.spec('path/to/spec.xpdl')*SPEC =*"])


def test_a_missing_spec_file_names_the_places_looked_at(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("SPEC = 'specs/nope.xpdl'\ndef test_it(spec):\n    pass\n")
    result = pytester.runpytest()
    result.stdout.fnmatch_lines(["*specs/nope.xpdl: file not found (looked at *"])


def test_a_broken_spec_fails_with_its_file_and_line_not_a_traceback(
        pytester: pytest.Pytester) -> None:
    (pytester.path / "broken.xpdl").write_text(
        '<?xml version="1.0"?>\n<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">\n'
        '<WorkflowProcesses><WorkflowProcess Id="w"><Activities>\n'
        '<Activity Id="a"/></Activities><Transitions>\n'
        '<Transition Id="t" From="a" To="missing"/>\n'
        '</Transitions></WorkflowProcess></WorkflowProcesses></Package>\n')
    pytester.makepyfile("SPEC = 'broken.xpdl'\ndef test_it(spec):\n    pass\n")
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*cannot load the spec: *broken.xpdl:*"])
    assert "Traceback" not in result.stdout.str()


def test_simulate_runs_a_script_given_as_plain_data(project: pytest.Pytester) -> None:
    project.makepyfile("""
        SPEC = "specs/dispenser.xpdl"

        def test_it(spec, simulate):
            result = simulate(spec, script=[("after trg_2 90s", "press_report")], until=9 * 3600)
            assert result.value("doses_taken") == 1
            assert result.value("report_latency_s") == 90
            assert [i.outcome for i in result.instances("notify_workflow")] == ["completed"]
            assert result.metric_names[0] == "doses_due"
    """)
    project.runpytest().assert_outcomes(passed=1)


def test_a_script_and_a_user_model_together_fail_once_with_the_reason(
        project: pytest.Pytester) -> None:
    project.makepyfile("""
        SPEC = "specs/dispenser.xpdl"

        def test_it(spec, simulate):
            simulate(spec, script=[("never", "press_report")],
                     user_model="specs/dispenser.users.toml", until=9 * 3600)
    """)
    # -rN: no short summary, whose line repeats the message only when the terminal is wide
    result = project.runpytest("-rN")
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    assert out.count("give script or user_model, not both") == 1
    assert "During handling" not in out


SEEDED = """
    SPEC = "specs/dispenser.xpdl"

    def test_one(spec, simulate, opspec_seed):
        result = simulate(spec, users=3, user_model="specs/dispenser.users.toml")
        print("RESULT one", opspec_seed, result.samples("report_latency_s"))

    def test_two(spec, simulate, opspec_seed):
        result = simulate(spec, users=3, user_model="specs/dispenser.users.toml")
        print("RESULT two", opspec_seed, result.samples("report_latency_s"))
"""


def _results(result: pytest.RunResult) -> dict[str, str]:
    return dict(re.findall(r"RESULT (\w+) (\d+ \[[^\]]*\])", result.stdout.str()))


def test_the_seed_option_makes_runs_reproducible_and_tests_independent(
        project: pytest.Pytester) -> None:
    project.makepyfile(SEEDED)
    first = _results(project.runpytest("-s", "--opspec-seed=5"))
    again = _results(project.runpytest("-s", "--opspec-seed=5"))
    other = _results(project.runpytest("-s", "--opspec-seed=6"))
    assert first == again and len(first) == 2
    assert first["one"] != first["two"]          # each test mixes in its own id
    assert first["one"] != other["one"]          # and the base seed matters


def test_the_same_seed_gives_the_same_runs_whatever_the_number_of_xdist_workers(
        project: pytest.Pytester) -> None:
    # each test writes what it drew (a worker's prints are not shown)
    project.makepyfile(test_drawn="""
        import pytest
        from opspec.testing import simulator_for

        SPEC = "specs/dispenser.xpdl"
        USERS = "specs/dispenser.users.toml"

        @pytest.fixture(scope="module")
        def shared(request):
            return simulator_for(request)(SPEC, users=3, user_model=USERS)

        @pytest.mark.parametrize("k", range(3))
        def test_drawn(spec, simulate, shared, k, request):
            result = simulate(spec, users=3, user_model=USERS)
            line = (request.node.name, result.seed, result.samples("report_latency_s"),
                    shared.seed, shared.samples("report_latency_s"))
            with open(f"drawn-{k}.txt", "w") as out:
                out.write(repr(line))
    """)

    def drawn(*args: str) -> list[str]:
        project.runpytest_subprocess("--opspec-seed=3", *args).assert_outcomes(passed=3)
        return [(project.path / f"drawn-{k}.txt").read_text() for k in range(3)]

    alone = drawn("-p", "no:xdist")
    assert drawn("-n", "2") == alone and len(set(alone)) == 3


def test_a_failing_test_reports_its_seed(project: pytest.Pytester) -> None:
    project.makepyfile("""
        SPEC = "specs/dispenser.xpdl"

        def test_it(spec, simulate):
            simulate(spec, until=3600)
            assert False
    """)
    result = project.runpytest("--opspec-seed=11")
    result.stdout.fnmatch_lines(["*opspec*", "seed * (from --opspec-seed=11 and the test id*"])
    # the id and the rootdir it is relative to: a rerun from another folder may differ
    result.stdout.fnmatch_lines([
        ("seed * (from --opspec-seed=11 and the test id 'test_a_failing_test_reports_its_seed.py"
         f"::test_it', relative to the rootdir {project.path}; simulate(seed=...) overrides it)")])


def test_device_url_skips_hardware_tests_without_it_and_passes_it_on(
        pytester: pytest.Pytester) -> None:
    pytester.makepyfile("""
        def test_board(device_url, device_profile):
            print("URL", device_url, device_profile)
    """)
    pytester.runpytest().assert_outcomes(skipped=1)
    result = pytester.runpytest("-s", "--device-url=loop://", "--device-profile=cart")
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["*URL loop:// cart*"])


def test_the_regen_golden_flag_reaches_the_tests(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("def test_it(regen_golden):\n    print('REGEN', regen_golden)\n")
    assert "REGEN False" in pytester.runpytest("-s").stdout.str()
    assert "REGEN True" in pytester.runpytest("-s", "--opspec-regen-golden").stdout.str()


def test_the_options_are_in_pytest_help(pytester: pytest.Pytester) -> None:
    text = pytester.runpytest("--help").stdout.str()
    for option in ("--opspec-seed", "--opspec-regen-golden", "--device-url", "--device-profile"):
        assert re.search(rf"^\s+{option}", text, re.MULTILINE), option


def test_the_fixtures_say_what_they_give_in_pytest_fixtures(pytester: pytest.Pytester) -> None:
    # `pytest --fixtures` shows a fixture's first paragraph: simulate's said only "see
    # Simulator", a class a test author never sees
    text = pytester.runpytest("--fixtures").stdout.str()
    shown = dict(re.findall(r"^(\w+) -- .*\n((?:    .*\n)+)", text, re.MULTILINE))
    assert "simulate(spec, users=1, days=None, until=None, script=None" in shown["simulate"]
    assert "SimulationResult" in shown["simulate"]
    assert 'SPEC = "path"' in shown["spec"] and "@pytest.mark.spec" in shown["spec"]
    assert "--opspec-seed" in shown["opspec_seed"]


def test_a_misspelt_argument_of_simulate_is_named_with_the_test_line(
        project: pytest.Pytester) -> None:
    # was a TypeError shown through the plugin's own frame (its source and locals)
    project.makepyfile(test_misspelt="""
        SPEC = "specs/dispenser.xpdl"

        def test_it(spec, simulate):
            simulate(spec, until=3600)
            simulate(spec, user=3, montors=["never dispense"])
    """)
    result = project.runpytest("-rN")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "test_misspelt.py:5: simulate(spec, user=3, montors=[[]\"never dispense\"[]])",
        "simulate() has no argument 'user': did you mean users=?",
        "simulate() has no argument 'montors': did you mean monitors=?",
        "it takes: spec, users, days, until, script, user_model, seed, engine_config, *"])
    out = result.stdout.str()
    assert "TypeError" not in out and "opspec/testing/" not in out


def test_a_failing_simulate_call_names_the_line_that_made_it(project: pytest.Pytester) -> None:
    # a test that simulates several times: which call was refused
    project.makepyfile(test_two_calls="""
        SPEC = "specs/dispenser.xpdl"

        def test_it(spec, simulate):
            simulate(spec, script=[("never", "press_report")], until=3600)
            simulate(spec, script=[("never", "press_reprot")], until=3600)
    """)
    result = project.runpytest("-rN")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "test_two_calls.py:5: simulate(spec, script=[[](\"never\", \"press_reprot\")[]], *",
        "simulate(): <script>: steps[[]0[]]: the script names activity 'press_reprot'*"])
