"""The coordination built-ins in constructed situations, written as a designer writes them:
which command the fixed-priority arbiter, the voter and the superposition choose at each
selection time, how the supervisor's mailboxes hold pushed data, and when a mode change takes
effect (including a mode whose workflows are loaded at run time)."""

from __future__ import annotations

from pathlib import Path

import pytest
from spec_text import Recorder, assign, builtin, compiled, field, process, task

from opspec.engine.builtin_performers import CallablePerformer
from opspec.engine.compiled import CompiledPackage
from opspec.engine.simulation import RunResult, Simulation


def set_at(pid: str, seconds: float, target: str, value: str) -> str:
    """A one-shot behaviour that writes ``target = value`` at ``seconds``."""
    return process(pid, [assign(f"{pid}_set", (target, value))],
                   StartTrigger=f"timer:after {seconds}s")


def run(model: CompiledPackage, until: float, **kw: object) -> tuple[Recorder, RunResult]:
    recorder = Recorder(["drive"], "motor_cmd")
    result = Simulation(model, performers={"motors": recorder}, keep_trace=True,
                        **kw).run(until=until)  # type: ignore[arg-type]
    return recorder, result


def selector(xml: str, period: str = "1s") -> str:
    """The selecting workflow: run the built-in every ``period``, then drive the motors."""
    return process("select", [builtin("choose", xml), task("drive", "drive")], Period=period,
                   fields=[field("motor_cmd", "STRING", '"stop"')])


# ---------------------------------------------------------------------- fixed-priority arbiter

ARBITER = ('<opspec:Arbiter Output="motor_cmd"><opspec:Input Ref="escape_cmd"/>'
           '<opspec:Input Ref="avoid_cmd"/><opspec:Input Ref="wander_cmd"/></opspec:Arbiter>')
COMMANDS = [field("escape_cmd", "STRING", '""'), field("avoid_cmd", "STRING", '""'),
            field("wander_cmd", "STRING", '""')]


def test_arbiter_gives_the_motors_the_highest_priority_command_set_at_each_selection(
        tmp_path: Path) -> None:
    model = compiled(tmp_path, [
        selector(ARBITER),
        set_at("wander_on", 0.5, "wander_cmd", '"forward"'),
        set_at("avoid_on", 2.5, "avoid_cmd", '"turn_left"'),
        set_at("escape_on", 4.5, "escape_cmd", '"back"'),
        set_at("escape_off", 6.5, "escape_cmd", '""'),
        set_at("avoid_off", 8.5, "avoid_cmd", '""'),
    ], fields=COMMANDS, applications=["drive"])
    recorder, _ = run(model, until=10.0)
    assert recorder.seen == [
        (0.0, None),                                  # nobody has a command yet
        (1.0, "forward"), (2.0, "forward"),
        (3.0, "turn_left"), (4.0, "turn_left"),       # avoid outranks wander
        (5.0, "back"), (6.0, "back"),                 # the manoeuvre outranks both
        (7.0, "turn_left"), (8.0, "turn_left"),       # cleared: the next one down wins again
        (9.0, "forward"),
    ]


def test_arbiter_keeps_a_command_until_its_behaviour_clears_it(tmp_path: Path) -> None:
    # a command is a data field: written once at 0.5 s, it still wins at 5 s (no staleness);
    # behaviours that stop proposing must write "" (the robot specs do, every period)
    model = compiled(tmp_path, [selector(ARBITER, period="5s"),
                                set_at("avoid_once", 0.5, "avoid_cmd", '"turn_left"')],
                     fields=[*COMMANDS[:2], field("wander_cmd", "STRING", '"forward"')],
                     applications=["drive"])
    recorder, _ = run(model, until=6.0)
    assert recorder.seen == [(0.0, "forward"), (5.0, "turn_left")]


# ---------------------------------------------------------------------- voter

VOTES = [field("vote_a", "STRING", '""'), field("vote_b", "STRING", '""'),
         field("vote_c", "STRING", '""')]


def voter_at(seconds: float, a: str, b: str, c: str, options: str) -> str:
    return process(f"vote_{int(seconds)}", [
        assign(f"cast_{int(seconds)}", ("vote_a", a), ("vote_b", b), ("vote_c", c)),
        builtin(f"count_{int(seconds)}",
                f'<opspec:Voter Output="motor_cmd" Options="{options}">'
                '<opspec:Input Ref="vote_a"/><opspec:Input Ref="vote_b"/>'
                '<opspec:Input Ref="vote_c"/></opspec:Voter>'),
        task(f"drive_{int(seconds)}", "drive")], StartTrigger=f"timer:after {seconds}s",
        fields=[field("motor_cmd", "STRING", '"stop"')])


@pytest.mark.parametrize(("votes", "options", "chosen"), [
    (('"left"', '"right"', '"left"'), "left right", "left"),
    (('"left"', '"right"', '"right"'), "left right", "right"),
    (('"left"', '"right"', '""'), "left right", "left"),
    (('"left"', '"right"', '""'), "right left", "right"),
    (('"stop"', '"forward"', '"forward"'), "stop forward", "forward"),
    (('""', '""', '""'), "left right", None),
    (('"jump"', '"left"', '"jump"'), "left right", "jump"),
    (('"jump"', '"left"', '""'), "left right", "left"),
], ids=["majority-left", "majority-right", "tie-first-option", "tie-follows-option-order",
        "majority-beats-option-order", "all-abstain", "unlisted-majority-counts",
        "tie-listed-before-unlisted"])
def test_voter_takes_the_majority_and_breaks_ties_by_the_order_of_its_options(
        tmp_path: Path, votes: tuple[str, str, str], options: str, chosen: str | None) -> None:
    model = compiled(tmp_path, [voter_at(1.0, *votes, options=options)], fields=VOTES,
                     applications=["drive"])
    recorder, _ = run(model, until=2.0)
    assert recorder.seen == [(1.0, chosen)]


# ---------------------------------------------------------------------- superposition

def blend(tmp_path: Path, proposals: dict[str, object], inputs: str) -> list[tuple[float, object]]:
    """Two behaviours' proposals (posted by a device, as vectors come from sensors) blended by
    a superposition at 1 s; returns what the motors were given."""
    model = compiled(tmp_path, [process("blend", [
        task("propose", "propose"),
        builtin("sum", f'<opspec:Superposition Output="velocity">{inputs}'
                       "</opspec:Superposition>"),
        task("drive", "drive")], StartTrigger="timer:after 1s",
        fields=[field("seek", "STRING", '""'), field("avoid", "STRING", '""'),
                field("velocity", "STRING", '""')])], applications=["propose", "drive"])
    recorder = Recorder(["drive"], "velocity")
    proposer = CallablePerformer({"propose": lambda _data: proposals})
    Simulation(model, performers={"motors": recorder, "sensors": proposer}).run(until=2.0)
    return recorder.seen


WEIGHTED = '<opspec:Input Ref="seek" Weight="0.7"/><opspec:Input Ref="avoid" Weight="0.8"/>'


@pytest.mark.parametrize(("seek", "avoid", "velocity"), [
    ([0.3, 0.0], [-0.1, 0.5], [pytest.approx(0.13), pytest.approx(0.4)]),
    ([0.3, 0.0], None, [pytest.approx(0.21), 0.0]),
    (0.3, 1.0, pytest.approx(1.01)),
    (None, None, None),
], ids=["vectors", "unset-input-left-out", "numbers", "nothing-proposed"])
def test_superposition_is_the_weighted_sum_of_the_proposals(
        tmp_path: Path, seek: object, avoid: object, velocity: object) -> None:
    assert blend(tmp_path, {"seek": seek, "avoid": avoid}, WEIGHTED) == [(1.0, velocity)]


def test_superposition_of_vectors_of_different_lengths_is_a_named_fault(tmp_path: Path) -> None:
    model = compiled(tmp_path, [process("blend", [
        builtin("sum", '<opspec:Superposition Output="velocity"><opspec:Input Ref="seek"/>'
                       '<opspec:Input Ref="avoid"/></opspec:Superposition>')],
        StartTrigger="timer:after 1s")], fields=[field("seek", "STRING", '""'),
                                                 field("avoid", "STRING", '""'),
                                                 field("velocity", "STRING", '""')])
    result = Simulation(model, keep_trace=True,
                        params={"seek": [1.0, 0.0], "avoid": [1.0]}).run(until=2.0)
    faults = [e for e in result.trace if e.kind == "activity.failed" and e.activity == "sum"]
    assert [f.data["message"] for f in faults] == [
        "superposition failed: superposition inputs are vectors of different lengths"]


# ---------------------------------------------------------------------- push / pull data

def test_pull_waits_for_the_next_push_and_each_value_is_delivered_once_oldest_first(
        tmp_path: Path) -> None:
    # three pushes at 1, 2, 3 s; a puller that asks at 0.5 s waits; two more ask at 4 s and
    # 5 s and get what the supervisor held, in order; a fourth asks at 6 s and is still waiting
    pushes = [process(f"push_{n}", [
        assign(f"measure_{n}", ("reading", str(n * 10))),
        builtin(f"give_{n}", '<opspec:PushData Channel="range" Ref="reading"/>')],
        StartTrigger=f"timer:after {n}s") for n in (1, 2, 3)]
    pulls = [process(f"pull_{n}", [
        builtin(f"take_{n}", '<opspec:PullData Channel="range" Ref="motor_cmd"/>'),
        task(f"use_{n}", "drive")], StartTrigger=f"timer:after {at}s",
        fields=[field("motor_cmd", "INTEGER", "0")])
        for n, at in ((1, 0.5), (2, 4.0), (3, 5.0), (4, 6.0))]
    model = compiled(tmp_path, [*pushes, *pulls], fields=[field("reading", "INTEGER", "0")],
                     applications=["drive"])
    recorder, result = run(model, until=10.0)
    assert recorder.seen == [(1.0, 10), (4.0, 20), (5.0, 30)]
    waiting = [e for e in result.trace if e.kind == "activity.started" and e.activity == "take_4"]
    assert waiting and not [e for e in result.trace if e.kind == "activity.completed"
                            and e.activity == "take_4"]


def test_mailboxes_are_separate_per_channel(tmp_path: Path) -> None:
    model = compiled(tmp_path, [
        process("push_left", [builtin("give_left",
                                      '<opspec:PushData Channel="left" Ref="left_cmd"/>')],
                StartTrigger="timer:after 1s"),
        process("push_right", [builtin("give_right",
                                       '<opspec:PushData Channel="right" Ref="right_cmd"/>')],
                StartTrigger="timer:after 2s"),
        process("take", [builtin("take_right",
                                 '<opspec:PullData Channel="right" Ref="motor_cmd"/>'),
                         task("use", "drive")], StartTrigger="timer:after 0.5s",
                fields=[field("motor_cmd", "STRING", '""')])],
        fields=[field("left_cmd", "STRING", '"turn_left"'),
                field("right_cmd", "STRING", '"turn_right"')], applications=["drive"])
    recorder, _ = run(model, until=5.0)
    assert recorder.seen == [(2.0, "turn_right")]


# ---------------------------------------------------------------------- mode change

MODES = ('<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="clean" Initial="true"/>'
         '<opspec:Mode Id="dock"{source}/></ExtendedAttribute>')


def cleaning_robot(tmp_path: Path, switch_at: float, *, source: str = "",
                   dock_here: bool = True) -> CompiledPackage:
    processes = [
        # a sweep takes 0.8 s before it drives: the one under way at the change never drives
        process("clean", [assign("sweep", ("motor_cmd", '"forward"'), seconds=0.8),
                          task("drive", "drive")],
                Period="1s", Mode="clean", fields=[field("motor_cmd", "STRING", '""')]),
        process("watch", [builtin("go_dock", '<opspec:ModeChange To="dock"/>')],
                StartTrigger=f"timer:after {switch_at}s"),
    ]
    if dock_here:
        processes.append(process("park", [assign("halt", ("motor_cmd", '"stop"')),
                                          task("park_drive", "drive")],
                                 Period="1s", Mode="dock",
                                 fields=[field("motor_cmd", "STRING", '""')]))
    return compiled(tmp_path, processes, applications=["drive"],
                    package_attributes=MODES.format(source=source))


def test_mode_change_takes_effect_at_the_simulated_time_of_the_activity(tmp_path: Path) -> None:
    recorder, result = run(cleaning_robot(tmp_path, switch_at=3.5), until=7.0)
    changes = [(e.time, e.data) for e in result.trace if e.kind == "mode.changed"]
    assert changes == [(3.5, {"from": "clean", "to": "dock"})]
    # periods keep their phase from time 0 whatever the mode: the clean instance of 3 s is
    # ended at 3.5 s before it drives; the dock workflow runs from its next period, 4 s
    assert recorder.seen == [(0.8, "forward"), (1.8, "forward"), (2.8, "forward"),
                             (4.0, "stop"), (5.0, "stop"), (6.0, "stop")]
    ended = [(e.time, e.process) for e in result.trace if e.kind == "process.terminated"]
    assert ended == [(3.5, "clean")]
    assert result.summary["mode"] == "dock"


def test_mode_change_loads_the_workflows_of_a_mode_given_by_source(tmp_path: Path) -> None:
    docking = compiled(tmp_path, [process("park", [assign("halt", ("motor_cmd", '"stop"')),
                                                   task("park_drive", "drive")], Period="1s",
                                           fields=[field("motor_cmd", "STRING", '""')])],
                       applications=["drive"],
                       name="docking")
    model = cleaning_robot(tmp_path, switch_at=2.5, source=' Source="docking.xpdl"',
                           dock_here=False)
    loads: list[tuple[str, float]] = []
    sim: Simulation

    def loader(source: str) -> CompiledPackage:
        loads.append((source, sim.env.now))
        return docking

    recorder = Recorder(["drive"], "motor_cmd")
    sim = Simulation(model, performers={"motors": recorder}, mode_loader=loader)
    result = sim.run(until=5.0)
    assert loads == [("docking.xpdl", 2.5)]
    assert recorder.seen == [(0.8, "forward"), (1.8, "forward"), (3.0, "stop"), (4.0, "stop")]
    assert result.summary["mode"] == "dock"


def test_workflows_loaded_for_a_mode_stop_when_the_mode_is_left(tmp_path: Path) -> None:
    docking = compiled(tmp_path, [process("park", [assign("halt", ("motor_cmd", '"stop"')),
                                                   task("park_drive", "drive")], Period="1s",
                                           fields=[field("motor_cmd", "STRING", '""')])],
                       applications=["drive"], name="docking")
    model = compiled(tmp_path, [
        process("clean", [assign("sweep", ("motor_cmd", '"forward"')), task("drive", "drive")],
                Period="1s", Mode="clean", fields=[field("motor_cmd", "STRING", '""')]),
        process("to_dock", [builtin("go_dock", '<opspec:ModeChange To="dock"/>')],
                StartTrigger="timer:after 1.5s"),
        process("to_clean", [builtin("go_clean", '<opspec:ModeChange To="clean"/>')],
                StartTrigger="timer:after 3.5s")],
        applications=["drive"],
        package_attributes=MODES.format(source=' Source="docking.xpdl"'))
    recorder = Recorder(["drive"], "motor_cmd")
    Simulation(model, performers={"motors": recorder},
               mode_loader=lambda _source: docking).run(until=6.0)
    assert recorder.seen == [(0.0, "forward"), (1.0, "forward"), (2.0, "stop"), (3.0, "stop"),
                             (4.0, "forward"), (5.0, "forward")]


class _Selecting:
    """A listener that selects some events (like the metrics and --timing do)."""

    def __init__(self, *selects: tuple[str, str | None, str | None]) -> None:
        self.selects = frozenset(selects)
        self.seen: list[tuple[float, str, str | None]] = []

    def __call__(self, event: object) -> None:
        self.seen.append((event.time, event.kind, event.process))  # type: ignore[attr-defined]


@pytest.mark.parametrize("dock_source", [False, True], ids=["dock-in-package", "dock-loaded"])
def test_metrics_and_timing_see_the_workflows_a_mode_change_loads(
        tmp_path: Path, dock_source: bool) -> None:
    from opspec.engine.timing import TimingListener

    docking = compiled(tmp_path, [process("park", [assign("halt", ("motor_cmd", '"stop"')),
                                                   task("park_drive", "drive")], Period="1s",
                                           fields=[field("motor_cmd", "STRING", '""')])],
                       applications=["drive"], name="docking")
    model = cleaning_robot(tmp_path, switch_at=2.5, dock_here=not dock_source,
                           source=' Source="docking.xpdl"' if dock_source else "")
    starts = _Selecting(("process.started", None, None))
    parks = _Selecting(("activity.completed", "park", "park_drive"))
    timing = TimingListener()
    result = Simulation(model, performers={"motors": Recorder(["drive"], "motor_cmd")},
                        listeners=[starts, parks, timing],
                        mode_loader=lambda _source: docking).run(until=5.0)
    # the same counts whether the dock workflow is in the package or loaded at 2.5 s
    assert len(starts.seen) == result.summary["instances"]["started"]
    assert [t for t, _, _ in parks.seen] == [3.0, 4.0]
    assert timing.summary()["park"]["completed"] == 2
