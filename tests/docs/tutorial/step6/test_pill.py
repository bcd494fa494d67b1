from opspec.testing import expect

SPEC = "pill.xpdl"


def test_answering_the_first_beep_takes_the_dose(spec, simulate):
    result = simulate(spec, script=[("after remind 2m", "press_taken")], until=10 * 3600)
    expect(result, "doses_taken == 1", "beeps == 1", "never activity tell_caregiver")


def test_no_answer_two_beeps_then_the_caregiver(spec, simulate):
    result = simulate(spec, script=[("never", "hear_beep")], until=10 * 3600)
    expect(result, "beeps == 2", "doses_missed == 1",
           "activity tell_caregiver within 20 min after process reminder_workflow")


def test_most_simulated_users_take_their_doses(spec, simulate):
    result = simulate(spec, users=50, days=2, user_model="pill.users.toml")
    expect(result, "rate doses_taken/doses_due >= 0.8 with 95% confidence")
