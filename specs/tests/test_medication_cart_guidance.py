"""Executable tests of specs/medication_cart_guidance.xpdl: the cart drives down the ward and
identifies the patient by RFID tag and wristband bar code."""

from __future__ import annotations

from typing import Any

from opspec.testing import assert_mean, assert_rate, check, happens_before

SPEC = "../medication_cart_guidance.xpdl"


def test_the_patient_is_confirmed_only_after_tag_and_bar_code(spec: Any,
                                                              simulate: Any) -> None:
    result = simulate(spec, until=300.0)
    check(result, happens_before("activity:scan", "activity:confirm"), spec=spec)


def test_carts_find_the_patient_within_five_minutes_on_average(spec: Any,
                                                               simulate: Any) -> None:
    result = simulate(spec, users=10, until=400.0, keep_trace=False)
    # the mean time is over the carts that found the patient: first, how many did (about
    # 95 % do within 400 s; "at least half" is then decided for almost every seed)
    found = result.metrics["patients_found"]["total"]
    assert_rate(result, (found, result.replications), at_least=0.5, confidence=0.95)
    assert_mean(result, "time_to_find_s", at_most=300.0, confidence=0.95)


def test_one_run_is_the_specs_run_length_unless_told_otherwise(spec: Any,
                                                               simulate: Any) -> None:
    """The cart declares opspec:RunLength PT10M: simulate() runs ten minutes by default."""
    result = simulate(spec)
    assert result.horizon == 600.0
    assert result.metrics["patients_found"]["total"] == 1
    assert simulate(spec, days=0.001).horizon == 86.4
