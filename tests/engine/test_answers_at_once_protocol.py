"""``AnswersAtOnce`` has the performer protocol's methods: a performer found to be one is then
of that class to the compiler, which calls ``answers_at_once`` natively (for a class outside
the protocol it made a mix of the two types and called through Python's protocol)."""

from __future__ import annotations

import inspect

import pytest

from opspec.engine.activities import AnswersAtOnce
from opspec.engine.performers import Performer


@pytest.mark.parametrize("name", ["attach", "offer", "withdraw"])
def test_the_protocols_methods_with_its_parameters(name: str) -> None:
    mine = inspect.signature(getattr(AnswersAtOnce, name)).parameters
    theirs = inspect.signature(getattr(Performer, name)).parameters
    assert list(mine) == list(theirs)


def test_the_base_answers_nothing_and_takes_no_work_item() -> None:
    base = AnswersAtOnce()
    base.attach(None)
    base.withdraw(None, "gone")
    assert base.answers_at_once("drive") is False
    with pytest.raises(NotImplementedError):
        base.offer(None)
