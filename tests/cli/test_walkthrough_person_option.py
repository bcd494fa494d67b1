"""`opspec walkthrough --person ID`: an identifier that cannot name a participant is refused
before anything opens, saying what to give."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("person", ["", "   ", "P07\nP08"])
def test_a_person_that_is_not_an_identifier_is_refused(person, capsys):
    with pytest.raises(SystemExit) as ended:
        main(["walkthrough", str(SPEC), "--no-record", "--person", person])
    assert ended.value.code == 2
    err = capsys.readouterr().err
    assert "--person" in err and "e.g. --person P07" in err
    assert "Traceback" not in err
