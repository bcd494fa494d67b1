"""The script language for scripted users: plain (when, action) data, files, and behaviour."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import ConfigurationError
from opspec.testing.script import load_script, parse_script
from opspec.testing.simulation import simulate

from .conftest import DISPENSER

EIGHT = 8 * 3600.0


@pytest.fixture(scope="module")
def spec() -> object:
    from opspec.engine.compiled import compile_package
    from opspec.xpdl.loader import load_spec

    return compile_package(load_spec(DISPENSER))


@pytest.mark.parametrize(("when", "action", "verb", "target", "delay", "absolute"), [
    (90, "complete walk_to_dispenser", "complete", "walk_to_dispenser", 90.0, False),
    ("90s", "walk_to_dispenser", "complete", "walk_to_dispenser", 90.0, False),
    ("+1m30s", "walk_to_dispenser", "complete", "walk_to_dispenser", 90.0, False),
    ("PT90S", "choose press_report", "choose", "press_report", 90.0, False),
    ("at 08:03", "raise trg_1", "raise", "trg_1", EIGHT + 180, True),
    ("at 08:00 on day 2", "press_report", "complete", "press_report", 86_400 + EIGHT, True),
    ("at 3600", "omit take_pill", "omit", "take_pill", 3600.0, True),
], ids=["seconds", "duration", "plus", "iso", "clock", "day-2", "at-seconds"])
def test_times_and_actions_read_as_documented(when: object, action: str, verb: str,
                                              target: str, delay: float,
                                              absolute: bool) -> None:
    (step,) = parse_script([(when, action)]).steps
    assert (step.verb, step.target, step.delay, step.absolute) == (verb, target, delay,
                                                                   absolute)


def test_never_each_after_and_otherwise() -> None:
    script = parse_script([("never", "press_report"), ("each after trg_2 5s", "take_pill"),
                           ("otherwise", "omit")])
    never, each = script.steps
    assert (never.verb, never.repeat) == ("omit", True)
    assert each.repeat and script.anchors == {1: "trg_2"} and script.otherwise == "omit"


@pytest.mark.parametrize(("entries", "message"), [
    ([("soon", "press_report")], r"steps\[0\]: cannot read the time 'soon'"),
    ([(-5, "press_report")], r"steps\[0\]: the time -5 is negative"),
    ([(0, "")], r"steps\[0\]: the action '' is not text"),
    ([("after trg_2", "press_report")], r"needs a name and a time"),
    ([("after trg_2 5s", "raise trg_1")], r"a 'raise' step takes an absolute time"),
    ([("otherwise", "dance")], r"'otherwise' takes one of complete, omit, wait"),
    ([("never", "omit press_report")], r"'never' takes one activity name"),
    ([(1, "press_report"), "press"], r"steps\[1\]: a step is a \(when, action\) pair"),
    ([("at 25:00", "raise trg_1")], r"time of day"),
    ("press_report", r"a script is a list of \(when, action\) pairs"),
], ids=["bad-time", "negative", "empty-action", "after-without-time", "raise-after",
        "otherwise", "never-verb", "not-a-pair", "bad-clock", "not-a-list"])
def test_bad_steps_are_explained(entries: object, message: str) -> None:
    with pytest.raises(ConfigurationError, match=message):
        parse_script(entries)  # type: ignore[arg-type]


def test_unknown_names_are_listed_against_the_spec(spec: object) -> None:
    with pytest.raises(ConfigurationError, match=r"trigger 'trg_3'.*known triggers: trg_1, trg_2"):
        simulate(spec, script=[("at 1", "raise trg_3")], until=60)  # type: ignore[arg-type]
    with pytest.raises(ConfigurationError, match=r"anchor 'alarm'.*activities and triggers"):
        simulate(spec, script=[("after alarm 5s", "press_report")],  # type: ignore[arg-type]
                 until=60)


@pytest.mark.parametrize("action", ["dispense", "omit record_missed", "fail notify_caregiver"])
def test_a_step_on_an_activity_the_user_is_never_offered_is_refused(spec: object,
                                                                    action: str) -> None:
    # the scripted user plays the user lane: a step on the device's dispense would never be
    # used, and the run went on as if it were not written (the dose taken all the same)
    target = action.split()[-1]
    with pytest.raises(ConfigurationError, match=(
            rf"step '.*{target}' names activity '{target}', which is never offered to the "
            r"user \(lane 'device' performs it in process 'notify_workflow'\), so the step "
            r"would never be used.*the user lane, whose activities are: choose_button, "
            r"hear_alarm, press_report, press_wrong_button, take_pill, walk_to_dispenser")):
        simulate(spec, script=[(10, action)], until=9 * 3600)  # type: ignore[arg-type]


@pytest.mark.parametrize("action", ["choose_button", "choose choose_button"])
def test_a_step_completing_a_choice_by_its_own_name_says_to_choose_an_alternative(
        spec: object, action: str) -> None:
    # was an ExecutionError mid-run: "call complete(item, choice=ACTIVITY_ID)"
    with pytest.raises(ConfigurationError, match=(
            r"<script>: steps\[0\]: the script's step '.*choose_button' names the choice "
            r"'choose_button', not one of its alternatives; write e.g. \(5, 'choose "
            r"press_report'\); its alternatives: press_report, press_wrong_button")):
        simulate(spec, script=[(5, action)], until=9 * 3600)  # type: ignore[arg-type]
    omitted = simulate(spec, script=[(5, "omit choose_button")], until=9 * 3600)  # type: ignore[arg-type]
    assert omitted.value("alarms") == 2


def test_steps_on_the_users_offers_choices_and_device_anchors_are_accepted(spec: object) -> None:
    result = simulate(spec, script=[("after sound_alarm 5s", "choose press_report"),  # type: ignore[arg-type]
                                    ("after dispense 5s", "take_pill"),
                                    ("at 08:30", "raise trg_1")], until=9 * 3600)
    assert result.value("doses_taken") == 1


def test_a_script_file_reads_pairs_and_tables(tmp_path: Path, spec: object) -> None:
    path = tmp_path / "late.toml"
    path.write_text('otherwise = "complete"\nsteps = [\n  ["after trg_2 120s", "press_report"],\n'
                    '  { when = "each 30s", do = "take_pill" },\n]\n')
    script = load_script(path)
    assert [s.target for s in script.steps] == ["press_report", "take_pill"]
    result = simulate(spec, script=path, until=9 * 3600)  # type: ignore[arg-type]
    assert result.value("report_latency_s") == 120.0


@pytest.mark.parametrize(("text", "message"), [
    ("steps = [[1]]", r"late.toml:1: steps\[0\]: a step is a \(when, action\) pair"),
    ('steps = []\nspeed = 2', r"late.toml:2: speed: unknown key"),
    ('otherwise = "later"', r"late.toml:1: otherwise: 'otherwise' takes one of"),
    ("steps = [", r"late.toml: the script is not valid TOML"),
    ('steps = [{ do = "x", after = 3 }]',
     r"late.toml:1: steps\[0\]: a step table has 'do'.*unknown key"),
], ids=["short-pair", "unknown-key", "bad-otherwise", "not-toml", "table-key"])
def test_bad_script_files_name_the_file_and_key(tmp_path: Path, text: str,
                                                message: str) -> None:
    path = tmp_path / "late.toml"
    path.write_text(text)
    with pytest.raises(ConfigurationError, match=message):
        load_script(path)


def test_a_raise_at_a_time_reports_without_pressing_anything(spec: object) -> None:
    result = simulate(spec, script=[("at 08:03", "raise trg_1"), ("never", "press_report")],  # type: ignore[arg-type]
                      until=9 * 3600)
    assert result.value("doses_taken") == 1 and result.value("report_latency_s") == 180.0


def test_otherwise_omit_is_a_user_who_ignores_everything(spec: object) -> None:
    result = simulate(spec, script=[("otherwise", "omit")], until=9 * 3600)  # type: ignore[arg-type]
    assert result.value("doses_missed") == 1 and result.value("alarms") == 3


def test_otherwise_wait_leaves_offers_pending(spec: object) -> None:
    result = simulate(spec, script=[("otherwise", "wait")], until=9 * 3600)  # type: ignore[arg-type]
    assert result.value("doses_missed") == 1
    assert {i.outcome for i in result.instances("user_workflow")} == {"open"}


def test_each_step_applies_to_every_dose_and_once_only_to_the_first(spec: object) -> None:
    once = simulate(spec, script=[("after trg_2 60s", "press_report")], days=1)  # type: ignore[arg-type]
    each = simulate(spec, script=[("each after trg_2 60s", "press_report")], days=1)  # type: ignore[arg-type]
    assert once.samples("report_latency_s.max") == [60.0]
    assert once.value("report_latency_s.min") == 0.0        # the later doses: reported at once
    assert each.value("report_latency_s.min") == each.value("report_latency_s.max") == 60.0


def test_after_an_activity_counts_from_its_completion(spec: object) -> None:
    result = simulate(spec, script=[("after sound_alarm 45s", "press_report")],  # type: ignore[arg-type]
                      until=9 * 3600)
    assert result.value("report_latency_s") == 45.0


def test_many_users_pool_metrics_and_keep_per_user_samples(spec: object) -> None:
    result = simulate(spec, users=5, user_model="dispenser-reference", seed=2)  # type: ignore[arg-type]
    assert result.replications == 5 and len(result.samples("doses_due")) == 5
    assert result.counts("doses_taken", "doses_due") == (result.value("doses_taken"), 20)
    assert result.value("report_latency_s.n") == len(result.observations("report_latency_s"))
    assert sum(result.samples("alarms")) == result.value("alarms")
    again = simulate(spec, users=3, user_model="dispenser-reference", seed=2)  # type: ignore[arg-type]
    assert again.samples("report_latency_s") == result.samples("report_latency_s")[:3]
    with pytest.raises(ConfigurationError, match="has 5 replications, so it has no single trace"):
        _ = result.trace
    with pytest.raises(ConfigurationError, match="'alarms_per_dose' is a ratio, not a count"):
        result.counts("alarms_per_dose", "doses_due")
