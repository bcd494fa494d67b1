"""A misspelt key of a protocol's [[variants]] table, or a table of its own, is refused at
file:line: key before any session runs: ``tld = "..."`` was read as no briefing at all, and
the variant's participants started without being told anything."""

from __future__ import annotations

from pathlib import Path

from opspec.cli import main


def test_a_misspelt_briefing_is_refused_at_its_line(protocol_file: Path, capsys) -> None:
    text = protocol_file.read_text(encoding="utf-8")
    protocol_file.write_text(text.replace('told = "Variant B', 'tld = "Variant B'),
                             encoding="utf-8")
    line = next(i for i, row in enumerate(protocol_file.read_text().splitlines(), 1)
                if row.startswith("tld"))
    assert main(["study", str(protocol_file)]) == 2
    err = capsys.readouterr().err
    assert f"{protocol_file}:{line}: variants[1].tld: unknown key 'tld'" in err
    assert "did you mean 'told'?" in err and "Traceback" not in err
    assert not (protocol_file.parent / "rec").exists()


def test_a_table_the_protocol_does_not_have_is_refused(protocol_file: Path, capsys) -> None:
    with protocol_file.open("a", encoding="utf-8") as out:
        out.write('\n[[varaints]]\nid = "C"\nspec = "dispenser-30s.xpdl"\n')
    assert main(["study", str(protocol_file)]) == 2
    err = capsys.readouterr().err
    assert ": varaints: unknown key 'varaints' (did you mean 'variants'?)" in err


def test_the_protocol_as_written_is_taken(protocol_file: Path, capsys) -> None:
    assert main(["study", str(protocol_file)]) == 0
    assert "P01: A to do, B to do" in capsys.readouterr().out


def test_every_variants_table_misspelt_is_said_to_be_misspelt(protocol_file: Path,
                                                              capsys) -> None:
    # with no [[variants]] left, it was said to have no variants at all
    text = protocol_file.read_text(encoding="utf-8")
    protocol_file.write_text(text.replace("[[variants]]", "[[varaints]]"), encoding="utf-8")
    assert main(["study", str(protocol_file)]) == 2
    err = capsys.readouterr().err
    assert ": varaints: unknown key 'varaints' (did you mean 'variants'?)" in err
    assert "needs at least one" not in err
