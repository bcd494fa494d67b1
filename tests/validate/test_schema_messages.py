"""What ``opspec validate --schema`` says of an element the WfMC schema rejects: the file's
own namespace is not spelled out in the element's name, and libxml2's full stop does not run
into the hint's semicolon."""

from __future__ import annotations

from pathlib import Path

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_a_rejected_element_is_named_as_written_in_the_file(tmp_path, capsys) -> None:
    text = (ROOT / "specs" / "medication_dispenser.xpdl").read_text(encoding="utf-8")
    spec = tmp_path / "bogus.xpdl"
    spec.write_text(text.replace("<Vendor>", "<Bogus/><Vendor>", 1), encoding="utf-8")
    assert main(["validate", "--schema", str(spec)]) == 1
    line = next(out for out in capsys.readouterr().out.splitlines() if "rejects this" in out)
    # it said "Element '{http://www.wfmc.org/2008/XPDL2.1}Bogus': ... Expected is
    # ( {http://www.wfmc.org/2008/XPDL2.1}Vendor ).; fix the element named ..."
    assert "Element 'Bogus': This element is not expected. Expected is ( Vendor ); fix" in line
    assert "{http" not in line and ".;" not in line


def test_an_element_of_another_namespace_keeps_it(tmp_path, capsys) -> None:
    text = (ROOT / "specs" / "medication_dispenser.xpdl").read_text(encoding="utf-8")
    spec = tmp_path / "foreign.xpdl"
    spec.write_text(text.replace("<Vendor>", '<x:Odd xmlns:x="urn:elsewhere"/><Vendor>', 1),
                    encoding="utf-8")
    assert main(["validate", "--schema", str(spec)]) == 1
    line = next(out for out in capsys.readouterr().out.splitlines() if "rejects this" in out)
    assert "'{urn:elsewhere}Odd'" in line
