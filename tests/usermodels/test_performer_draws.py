"""The stochastic user's fast draws give numpy's own floats from the same stream positions.

``StochasticUser`` takes its uniforms from PCG64's raw 64-bit output and writes a lognormal
duration's draw out in ``offer`` (issue 31: the user model runs interpreted in both builds).
numpy documents ``Generator.random`` as "Return random floats in the half-open interval
[0.0, 1.0)", and its PCG64 source defines the double as ``(next64 >> 11) * (1.0 /
9007199254740992.0)`` (numpy/random/src/pcg64/pcg64.h); these tests pin that identity and
the lognormal's on many values, so a numpy that changed either would fail here rather than
silently change every evaluation's numbers.
"""

from __future__ import annotations

import types

import numpy as np
import pytest

from opspec.engine.performers import WorkItem
from opspec.usermodels import parse_user_model, performer
from opspec.usermodels.parametric import LogNormal
from opspec.usermodels.performer import _TWO_TO_MINUS_53, StochasticUser


def _user(rng: np.random.Generator) -> StochasticUser:
    return StochasticUser(parse_user_model({"format": "opspec-user-model", "version": 1,
                                            "activities": {}}), rng)


@pytest.mark.parametrize("seed", [0, 1, 7, 2026])
def test_a_raw_uniform_is_generator_random_at_the_same_position(seed: int) -> None:
    fast, reference = np.random.default_rng(seed), np.random.default_rng(seed)
    user = _user(fast)
    assert user._raw is not None     # default_rng is PCG64: the raw path is the one taken
    # interleaved with the other draws a user makes, so the positions must stay in step
    for i in range(20_000):
        assert user._uniform() == reference.random()
        if i % 3 == 0:
            assert fast.standard_normal() == reference.standard_normal()
        if i % 7 == 0:
            assert int(fast.integers(3)) == int(reference.integers(3))
    assert fast.bit_generator.state == reference.bit_generator.state


def test_another_bit_generator_goes_through_generator_random() -> None:
    fast = np.random.Generator(np.random.MT19937(5))
    reference = np.random.Generator(np.random.MT19937(5))
    user = _user(fast)
    assert user._raw is None
    assert [user._uniform() for _ in range(1000)] == [reference.random() for _ in range(1000)]


def test_the_uniform_is_exactly_the_top_53_bits() -> None:
    # the extremes of the identity: the smallest and largest raw words
    assert (0 >> 11) * _TWO_TO_MINUS_53 == 0.0
    assert ((2**64 - 1) >> 11) * _TWO_TO_MINUS_53 == 1.0 - 2.0**-53 < 1.0


@pytest.mark.parametrize("median, sigma", [(60.0, 0.6), (20.0, 0.4), (1e-3, 2.5), (3e4, 0.05)])
def test_offer_draws_a_lognormal_duration_as_lognormal_sample(median: float,
                                                              sigma: float) -> None:
    model = parse_user_model({
        "format": "opspec-user-model", "version": 1,
        "activities": {"walk": {"duration": {"kind": "lognormal", "median": median,
                                             "sigma": sigma}}}})
    duration = model.activity("walk").duration
    assert type(duration) is LogNormal
    fast, reference = np.random.default_rng(11), np.random.default_rng(11)
    user = StochasticUser(model, fast)
    finished: list[float] = []

    class Session:       # only what offer asks of the engine: the clock and a callback
        now = 0.0

        def call_later(self, delay: float, callback: object) -> None:
            finished.append(delay)

    user.attach(Session())  # type: ignore[arg-type]
    for key in range(5000):
        user.offer(WorkItem(key, "p", key, "walk", "Walk", "user", "user", 0.0))
    assert finished == [duration.sample(reference) for _ in range(5000)]
    assert fast.bit_generator.state == reference.bit_generator.state


@pytest.mark.parametrize("seed", [0, 3, 2026])
def test_the_users_normal_is_generator_standard_normal_at_the_same_position(seed: int) -> None:
    """The user's standard normal (numpy's ziggurat called on the bit generator itself)
    gives ``Generator.standard_normal()``'s floats and stream positions, interleaved with
    the user's other draws; the tail of the ziggurat (about 0.7 % of draws) included."""
    fast, reference = np.random.default_rng(seed), np.random.default_rng(seed)
    user = _user(fast)
    normal = performer._standard_normal(fast)
    assert normal != fast.standard_normal      # the C function is the one taken
    for i in range(30_000):
        assert float(normal()) == float(reference.standard_normal())
        if i % 2 == 0:
            assert user._uniform() == reference.random()
        if i % 11 == 0:
            assert int(fast.integers(5)) == int(reference.integers(5))
    assert fast.bit_generator.state == reference.bit_generator.state


@pytest.mark.skipif(not isinstance(performer._standard_normal, types.FunctionType),
                    reason="compiled, the module's lookup cannot be replaced")
def test_without_the_c_function_the_user_calls_the_method(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(performer, "_C_NORMAL", [None])
    rng = np.random.default_rng(4)
    assert performer._standard_normal(rng) == rng.standard_normal
