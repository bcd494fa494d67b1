"""References across files: ExternalPackages and SubFlows resolve relative to the referencing
file or by Package Id; cycles and missing files are reported at the reference, never followed
forever."""

from __future__ import annotations

from pathlib import Path

from opspec.errors import Severity
from opspec.xpdl import load_package

DATA = Path(__file__).parent / "data"


def test_subflow_into_an_external_package_resolves_relative_to_the_file() -> None:
    result = load_package(DATA / "subflow_main.xpdl")
    assert result.ok, [str(d) for d in result.diagnostics]
    assert set(result.packages) == {"main_ok", "lib"}
    assert result.packages["lib"].process("helper") is not None


def test_external_package_cycle_is_reported_naming_the_cycle() -> None:
    result = load_package(DATA / "package_cycle_a.xpdl")
    assert result.package is not None and set(result.packages) == {"cycle_a", "cycle_b"}
    [cycle] = [d for d in result.diagnostics if d.code == "package-cycle"]
    assert "package_cycle_a.xpdl -> package_cycle_b.xpdl -> package_cycle_a.xpdl" in cycle.message
    assert cycle.location.path.endswith("package_cycle_b.xpdl") and cycle.location.line == 4


def test_subflow_cycle_across_packages_is_an_error() -> None:
    result = load_package(DATA / "subflow_cycle_main.xpdl")
    [cycle] = [d for d in result.diagnostics if d.code == "subflow-cycle"]
    assert cycle.severity is Severity.ERROR
    assert "main:caller -> other:callee -> main:caller" in cycle.message or \
        "other:callee -> main:caller -> other:callee" in cycle.message
    assert cycle.location.line is not None


def test_synchronous_self_call_is_a_subflow_cycle() -> None:
    result = load_package(DATA / "subflow_self_cycle.xpdl")
    [cycle] = [d for d in result.diagnostics if d.code == "subflow-cycle"]
    assert "self:p -> self:p" in cycle.message and cycle.location.line == 6


def test_missing_external_package_is_reported_at_the_reference() -> None:
    result = load_package(DATA / "missing_external.xpdl")
    [missing] = result.errors
    assert missing.code == "missing-external-package"
    assert missing.location.path.endswith("missing_external.xpdl") and missing.location.line == 4


def test_renamed_external_file_is_found_by_package_id(tmp_path: Path) -> None:
    (tmp_path / "main.xpdl").write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="m"><ExternalPackages>'
        '<ExternalPackage Id="Repo" href="Repo.xpdl"/></ExternalPackages></Package>')
    (tmp_path / "exported__Repo.xpdl").write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="Repo"/>')
    result = load_package(tmp_path / "main.xpdl")
    assert result.ok and set(result.packages) == {"m", "Repo"}


def test_remote_external_package_is_never_fetched(tmp_path: Path) -> None:
    (tmp_path / "main.xpdl").write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="m"><ExternalPackages>'
        '<ExternalPackage Id="r" href="http://example.invalid/r.xpdl"/></ExternalPackages></Package>')
    result = load_package(tmp_path / "main.xpdl")
    assert [d.code for d in result.diagnostics] == ["remote-external-package"]


def test_broken_external_package_reports_its_own_file(tmp_path: Path) -> None:
    (tmp_path / "main.xpdl").write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="m"><ExternalPackages>'
        '<ExternalPackage Id="b" href="broken.xpdl"/></ExternalPackages></Package>')
    (tmp_path / "broken.xpdl").write_text("<Package><oops></Package>")
    result = load_package(tmp_path / "main.xpdl")
    [error] = result.errors
    assert error.code == "not-well-formed" and error.location.path.endswith("broken.xpdl")
    assert result.package is not None


def test_unresolved_cross_package_subflow(tmp_path: Path) -> None:
    (tmp_path / "main.xpdl").write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="m"><WorkflowProcesses>'
        '<WorkflowProcess Id="p"><Activities><Activity Id="a"><Implementation>'
        '<SubFlow Id="q" PackageRef="nowhere"/></Implementation></Activity></Activities>'
        "</WorkflowProcess></WorkflowProcesses></Package>")
    result = load_package(tmp_path / "main.xpdl")
    assert [d.code for d in result.errors] == ["unresolved-subflow"]
