"""``opspec evaluate --resume`` of a run whose replications are all stored (it only writes the
report) says so once: "resuming, 800 of 800 users already stored". It went on with "800/800
users (0/s, done)", a rate of nothing."""

from __future__ import annotations

import io

from opspec.evaluation.progress import LogProgress


def test_nothing_to_run_is_said_once() -> None:
    out = io.StringIO()
    progress = LogProgress(out, label="users")
    progress.start(800, 800)
    progress.finish()
    assert out.getvalue() == "opspec evaluate: resuming, 800 of 800 users already stored\n"


def test_a_resumed_run_that_ran_some_still_ends_with_its_line() -> None:
    out = io.StringIO()
    progress = LogProgress(out, label="users")
    progress.start(800, 700)
    progress.advance(100)
    progress.finish()
    assert out.getvalue().splitlines()[-1].startswith("opspec evaluate: 800/800 users (")
    assert out.getvalue().endswith(", done)\n")
