"""Same seed -> same trace; random streams per entity, independent of the others."""

from __future__ import annotations

import numpy as np
import pytest
from builders import act, pkg, proc
from engine_runs import run

from opspec.engine.random import Streams, named_stream, user_stream
from opspec.model import DeclaredDistribution as Distribution

LOGNORMAL = Distribution(kind="lognormal", parameters=(("median", 60.0), ("sigma", 0.6)))


def _model() -> object:
    return pkg(proc("p", [act("walk", duration=LOGNORMAL), act("rest", duration=Distribution(
        kind="UniformDistribution", parameters=(("min", 1.0), ("max", 5.0))))],
        [("walk", "rest")], start="period:100"))


def _trace(seed: int) -> list[dict[str, object]]:
    result = run(_model(), seed=seed, until=1000.0)
    return [e.to_json() for e in result.trace or ()]


def test_same_seed_gives_an_identical_trace() -> None:
    assert _trace(7) == _trace(7)


def test_numpy_integers_work_as_seed_scope_and_until() -> None:
    # A seed taken from a numpy array must give the ints' run, compiled or not (the compiled
    # engine itself accepts only Python ints and floats).
    numpy_run = run(_model(), seed=np.int64(7), until=np.int64(1000), scope=(np.int32(2),))
    int_run = run(_model(), seed=7, until=1000.0, scope=(2,))
    assert [e.to_json() for e in numpy_run.trace or ()] == [
        e.to_json() for e in int_run.trace or ()]


def test_a_float_seed_is_refused() -> None:
    with pytest.raises(TypeError):
        run(_model(), seed=7.5, until=10.0)  # type: ignore[arg-type]


def test_different_seeds_give_different_durations() -> None:
    assert _trace(7) != _trace(8)


def test_declared_durations_are_drawn_from_the_distribution() -> None:
    result = run(_model(), seed=3, until=100_000.0)
    starts = {}
    walks = []
    for e in result.trace or ():
        if e.activity == "walk" and e.kind == "activity.started":
            starts[e.instance] = e.time
        elif e.activity == "walk" and e.kind == "activity.completed":
            walks.append(e.time - starts[e.instance])
    assert len(walks) > 900
    assert 55 < float(np.median(walks)) < 65


def test_user_stream_matches_seed_sequence_spawn_whatever_the_number_of_users() -> None:
    for n in (5, 50):
        spawned = np.random.SeedSequence(11).spawn(n)[3]
        assert np.random.default_rng(spawned).random() == user_stream(11, 3).random()


def test_named_streams_are_stable_and_scoped_per_household() -> None:
    a = named_stream(1, "p/walk").random()
    assert named_stream(1, "p/walk").random() == a
    assert named_stream(1, "p/rest").random() != a
    assert named_stream(1, "p/walk", scope=(2,)).random() != a
    streams = Streams(1, scope=(4,))
    assert streams.stream("x") is streams.stream("x")
    assert streams.user().random() == user_stream(1, 4).random()
