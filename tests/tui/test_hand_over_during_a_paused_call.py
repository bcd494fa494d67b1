"""With ``--on-call pause``, handing the lane to the user model while the device's call had
paused the clock left it paused ("PAUSED | model performs your lane"): the model, which is
never slowed down (a call's real time gives the speed back at once when handed over), stood
still until someone found space. The call's pause now ends with the hand-over; a pause the
person made stays."""

from __future__ import annotations

from opspec.tui.session import WalkSession


def test_the_call_s_pause_ends_when_the_model_takes_the_lane(compiled, model_factory):
    session = WalkSession(compiled, on_call="pause", model_factory=model_factory)
    session.skip_until_user()                          # 08:00: the alarm pauses the clock
    assert session.paused and session.calling
    assert session.hand_over()
    assert not session.paused
    at = session.now
    session.advance(5.0)                               # the model's lane runs on
    assert session.now > at


def test_a_pause_of_the_person_s_own_stays(compiled, model_factory):
    session = WalkSession(compiled, on_call="pause", model_factory=model_factory)
    session.paused = True                              # the coordinator paused it
    session.skip_until_user()
    assert session.paused and session.calling
    session.hand_over()
    assert session.paused                              # theirs: space resumes it


def test_a_call_s_pause_the_person_resumed_and_paused_again_stays(compiled, model_factory):
    session = WalkSession(compiled, on_call="pause", model_factory=model_factory)
    session.skip_until_user()
    session.paused = False                             # space
    session.paused = True                              # space: now the person's pause
    session.hand_over()
    assert session.paused
