"""Fitting user models from traces, and the `opspec fit` command."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from opspec.cli import main
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import UserModelError
from opspec.usermodels import ActivityModel, UserModel, load_user_model
from opspec.usermodels.distributions import ExGaussian, LogNormal
from opspec.usermodels.duration_family import fit_duration
from opspec.usermodels.errors import Omission
from opspec.usermodels.fitting import fit_traces

from .fakes import DispenserLane, FakeSession, make_item, write_trace

DAY = 86_400.0


@pytest.fixture(scope="module")
def dispenser_traces(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Two trace files of the reference user (1,500 dose cycles each)."""
    folder = tmp_path_factory.mktemp("traces")
    model = load_user_model("dispenser-reference")
    paths = []
    for seed in (1, 2):
        session = FakeSession()
        lane = DispenserLane(session, model.performer(np.random.default_rng(seed)))
        for day in range(375):
            for hour in (8, 12, 18, 22):
                lane.dose(day * DAY + hour * 3600.0)
        session.run()
        paths.append(write_trace(folder / f"run{seed}.jsonl", session.events))
    return paths


@pytest.fixture(scope="module")
def fitted(dispenser_traces: list[Path]):
    return fit_traces(dispenser_traces, name="fitted")


def test_fit_recovers_the_walk_lognormal(fitted) -> None:
    walk = fitted.model.activities["walk_to_dispenser"].duration
    n = fitted.observations.durations["walk_to_dispenser"].__len__()
    assert isinstance(walk, LogNormal)
    assert walk.mu == pytest.approx(math.log(60), abs=5 * 0.6 / math.sqrt(n))
    assert walk.sigma == pytest.approx(0.6, rel=0.05)


def test_fit_recovers_the_not_heard_rate_with_its_interval(fitted) -> None:
    fit = next(f for f in fitted.fits if f.activity == "hear_alarm")
    _omitted, answered, (low, high) = fit.omission
    p = fitted.model.activities["hear_alarm"].omission.probability
    assert p == pytest.approx(0.15, abs=5 * math.sqrt(0.15 * 0.85 / answered))
    assert low < p < high


def test_fit_recovers_the_wrong_button_commission(fitted) -> None:
    choose = fitted.model.activities["choose_button"]
    assert choose.intended == "press_report"
    assert choose.commission.alternatives == ("press_wrong_button",)
    assert choose.commission.max_per_instance == 1
    n = len(fitted.observations.picks["choose_button"])
    assert choose.commission.probability == pytest.approx(0.05,
                                                           abs=5 * math.sqrt(0.0475 / n))


def test_fit_finds_the_busy_behaviour(fitted) -> None:
    busy = fitted.model.busy
    assert busy is not None and busy.ignore == frozenset({"hear_alarm"})
    assert "walk_to_dispenser" in busy.engaged


def test_constant_durations_fit_as_constants(fitted) -> None:
    assert fitted.model.activities["press_wrong_button"].duration.mean == pytest.approx(10.0)


def test_ex_gaussian_data_pick_the_ex_gaussian_by_aic() -> None:
    truth = ExGaussian(2.0, 0.3, 1.5)
    x = truth.sample_many(np.random.default_rng(4), 3000)
    dist, chosen, aic, _ = fit_duration(x.tolist())
    assert chosen == "exgauss" and aic["exgauss"] < aic["lognormal"]
    assert isinstance(dist, ExGaussian)
    assert dist.tau == pytest.approx(1.5, rel=0.1)
    assert dist.mu == pytest.approx(2.0, abs=0.1)


def test_lognormal_data_pick_the_lognormal_by_aic() -> None:
    x = LogNormal(math.log(30), 0.8).sample_many(np.random.default_rng(5), 3000)
    assert fit_duration(x.tolist())[1] == "lognormal"


def test_fitted_choice_probabilities_when_people_end_differently(tmp_path: Path) -> None:
    session = FakeSession()
    model = UserModel(name="t", activities={"c": ActivityModel(probabilities=(("a", 0.2),
                                                                               ("b", 0.8)))})
    user = model.performer(np.random.default_rng(0))
    user.attach(session)
    for i in range(2000):
        item = make_item("c", i, choices=("a", "b"))
        session.log(EventKind.ACTIVITY_OFFERED, item, choices=["a", "b"])
        user.offer(item)
    session.run()
    result = fit_traces([write_trace(tmp_path / "t.jsonl", session.events)])
    probs = dict(result.model.activities["c"].probabilities)
    assert probs["a"] == pytest.approx(0.2, abs=5 * math.sqrt(0.16 / 2000))


def test_cli_writes_a_model_that_loads_back(dispenser_traces: list[Path], tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "people.users.toml"
    assert main(["fit", *map(str, dispenser_traces), "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    text = out.read_text()
    assert "chosen by AIC" in text and "Wilson 95 % interval" in text
    model = load_user_model(out)
    assert model.name == "people"
    model.validate_against(["hear_alarm", "walk_to_dispenser", "press_report",
                            "press_wrong_button", "take_pill"],
                           choices={"choose_button": ["press_report", "press_wrong_button"]})


def test_cli_accepts_a_folder_of_traces(dispenser_traces: list[Path], tmp_path: Path) -> None:
    out = tmp_path / "m.toml"
    assert main(["fit", str(dispenser_traces[0].parent), "-o", str(out)]) == 0
    assert load_user_model(out).activities["take_pill"].duration.mean > 0


BAD_TRACES = {
    "empty": ("", r"empty trace"),
    "no-header": ('{"time": 0, "kind": "run.started"}\n', r":1: not an opspec trace"),
    "bad-json": ('{"format": "opspec-trace", "version": 1}\n{"time": 1,\n',
                 r":2: not valid JSON"),
    "future-version": ('{"format": "opspec-trace", "version": 9}\n',
                       r":1: unsupported trace version 9"),
    "no-user-lane": (('{"format": "opspec-trace", "version": 1}\n'
                     '{"time": 0, "kind": "activity.offered", "activity": "x", "lane": '
                     '"device", "instance": 1}\n'), (r"no activity of lane 'user'.*lanes seen: "
                     r"device")),
    "event-without-time": ('{"format": "opspec-trace", "version": 1}\n{"kind": "x"}\n',
                           r":2: not a trace event"),
}


@pytest.mark.parametrize(("text", "message"), BAD_TRACES.values(), ids=BAD_TRACES.keys())
def test_unusable_traces_are_clear_errors(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "t.jsonl"
    path.write_text(text)
    with pytest.raises(UserModelError, match=message):
        fit_traces([path])


@pytest.mark.parametrize(("line", "message"), [
    ('{"kind": "activity.started", "x": "abc\x01"}\n',
     ":1: not valid JSON: Invalid control character at column 39 (each line"),
    ('{"kind": "activity.started", "x": "abc\n',
     ":1: not valid JSON: Invalid control character at column 39 (each line"),
    ('{"kind": "activity.started", "x": "abc',
     ":1: not valid JSON: Unterminated string starting at column 35 (each line"),
    ('{"time": 1,\n', (":1: not valid JSON: Expecting property name enclosed in double "
                       "quotes at the end of the line (each line")),
], ids=["control-character", "newline-in-string", "unterminated", "line-ends-early"])
def test_a_line_that_is_not_json_is_a_whole_sentence_with_its_column(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], line: str, message: str) -> None:
    # json's own message for these ends in "at" ("Invalid control character at"): the column
    # it leaves to its str() was lost, and the sentence cut off before the hint.
    path = tmp_path / "bad.jsonl"
    path.write_text(line, encoding="utf-8")
    status = main(["fit", str(path), "-o", str(tmp_path / "f.toml")])
    assert status != 0
    assert f"{path}{message}" in capsys.readouterr().err


def test_cli_reports_a_missing_trace_without_a_traceback(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["fit", str(tmp_path / "missing.jsonl"), "-o", str(tmp_path / "m.toml")])
    err = capsys.readouterr().err
    assert status == 2
    assert "missing.jsonl: cannot read trace: No such file or directory" in err
    assert "Traceback" not in err


def test_omissions_without_completions_still_fit(tmp_path: Path) -> None:
    item = make_item("hear", 1)
    events = [TraceEvent(0.0, EventKind.ACTIVITY_OFFERED, instance=1, activity="hear",
                         lane="user"),
              TraceEvent(0.0, EventKind.ACTIVITY_OMITTED, instance=1, activity="hear",
                         lane="user", data={"reason": "not heard"})]
    del item
    model = fit_traces([write_trace(tmp_path / "t.jsonl", events)]).model
    assert model.activities["hear"].omission == Omission(
        1.0, source=model.activities["hear"].omission.source)
