"""An Application id served by several bound performers: the activity's performer chooses.

XPDL 2.1 (WfMC-TC-1025, 7.6): "Performers ... the resource that is requested to or should
perform the activity". Two motors, each its own participant, both offer ``drive``: the
activity performed by the left motor is driven by the left motor's performer. (The engine
had routed every ``drive`` to whichever performer was bound last, silently.)
"""

from __future__ import annotations

from builders import app, pkg, proc, task

from engine_runs import completed, events, run
from opspec.engine.builtin_performers import CallablePerformer
from opspec.engine.config import EngineConfig
from opspec.engine.registry import PerformerRegistry, SharedApplication


def _two_motors(third: str | None = None):
    acts = [task("left", "drive", performer="motor_left"),
            task("right", "drive", performer="motor_right")]
    trans = [("left", "right")]
    if third is not None:
        acts.append(task("other", "drive", performer=third))
        trans.append(("right", "other"))
    return pkg(proc("p", acts, trans),
               participants=[("motor_left", "SYSTEM"), ("motor_right", "SYSTEM"),
                             ("wheel", "SYSTEM")],
               applications=[app("drive")])


def test_each_activity_is_driven_by_its_own_performers_device(config: EngineConfig) -> None:
    calls: list[str] = []
    left = CallablePerformer({"drive": lambda _d: calls.append("left")})
    right = CallablePerformer({"drive": lambda _d: calls.append("right")})
    result = run(_two_motors(), performers={"motor_left": left, "motor_right": right},
                 config=config)
    assert completed(result) == ["left", "right"]
    assert calls == ["left", "right"]
    # and in the other binding order too: the order of binding does not choose
    calls.clear()
    result = run(_two_motors(), performers={"motor_right": right, "motor_left": left},
                 config=config)
    assert calls == ["left", "right"]


def test_an_activity_whose_performer_serves_none_of_them_fails_saying_why(
        config: EngineConfig) -> None:
    calls: list[str] = []
    left = CallablePerformer({"drive": lambda _d: calls.append("left")})
    right = CallablePerformer({"drive": lambda _d: calls.append("right")})
    result = run(_two_motors(third="wheel"), performers={"motor_left": left,
                                                          "motor_right": right},
                 config=config)
    assert calls == ["left", "right"]          # not guessed: neither motor drives 'other'
    failed = events(result, "activity.failed", activity="other")
    assert failed and failed[0].data["exception"] == "AmbiguousApplication"
    message = failed[0].data["message"]
    assert "'drive'" in message and "motor_left, motor_right" in message
    assert "'wheel'" in message


def test_one_performer_per_application_is_bound_as_itself() -> None:
    one = CallablePerformer({"drive": lambda _d: None})
    registry = PerformerRegistry({"motor_left": one, "wheel": one})
    assert registry.applications["drive"] is one          # no dispatcher without a need
    other = CallablePerformer({"drive": lambda _d: None})
    registry.bind("motor_right", other)
    shared = registry.applications["drive"]
    assert isinstance(shared, SharedApplication) and shared.servers == [one, other]
    assert list(registry.performers()) == [one, other, shared]   # each attached once


def test_work_of_a_participant_bound_to_none_goes_to_the_one_general_server(
        config: EngineConfig) -> None:
    """A world's devices are bound under a name that is no participant ("world") and serve
    every operation; a device bound to one participant serves the same id: the work of
    other participants stays with the world (as the world and a bound device share
    ``drive`` when one motor is bound to a port)."""
    calls: list[str] = []
    world = CallablePerformer({"drive": lambda _d: calls.append("world")})
    port = CallablePerformer({"drive": lambda _d: calls.append("port")})
    result = run(_two_motors(third="wheel"), performers={"world": world, "motor_left": port},
                 config=config)
    assert completed(result) == ["left", "right", "other"]
    assert calls == ["port", "world", "world"]
