"""Hostile and clumsy input at the reader (issue 17): pipes and devices are refused at once,
line numbers stay exact past libxml2's 16-bit range, a file that declares UTF-8 but is not is
reported as such, and ExternalPackage hrefs stay inside the spec's folder tree."""

from __future__ import annotations

import os
import stat
import threading
from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.xpdl import load_package, parse_bytes
from opspec.xpdl.reader import XmlReadError, line_of, not_a_file, read_file, read_tree

XPDL21 = "http://www.wfmc.org/2008/XPDL2.1"
XPDL10 = "http://www.wfmc.org/2002/XPDL1.0"


def big_spec(padding: int, *, namespace: str = XPDL21, tool: bool = False) -> tuple[str, dict]:
    """A package with ``padding`` lines of vendor data before its process, and where its
    interesting elements are (1-based lines)."""
    head = (f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{namespace}" Id="p">\n'
            "  <ExtendedAttributes><ExtendedAttribute Name=\"padding\">\n")
    pad = "".join(f'    <Pad n="{i}"/>\n' for i in range(padding))
    body = ("  </ExtendedAttribute></ExtendedAttributes>\n"
            "  <WorkflowProcesses>\n"
            '    <WorkflowProcess Id="main">\n'
            "      <Activities>\n"
            '        <Activity Id="a">\n'
            + ('          <Implementation><Tool Id="app"/></Implementation>\n' if tool else
               "          <Implementation><No/></Implementation>\n")
            + "        </Activity>\n"
            '        <Activity Id="b"\n'
            '                  Name="a start tag on two lines">\n'
            "          <Route/>\n"
            "        </Activity>\n"
            "      </Activities>\n"
            "      <Transitions>\n"
            '        <Transition Id="t1" From="a" To="b"/>\n'
            '        <Transition Id="t2" From="b" To="nowhere"/>\n'
            "      </Transitions>\n"
            "    </WorkflowProcess>\n"
            "  </WorkflowProcesses>\n"
            "</Package>\n")
    text = head + pad + body
    lines = text.splitlines()

    def at(marker: str) -> int:
        return next(n for n, line in enumerate(lines, 1) if marker in line)

    return text, {"a": at('Id="a"'), "b": at("two lines"), "t1": at('Id="t1"'),
                  "t2": at('Id="t2"'), "tool": at("<Tool") if tool else 0}


# ---------------------------------------------------------------- line numbers past 65,535


def test_line_numbers_past_65535_are_exact(tmp_path: Path) -> None:
    text, where = big_spec(70_000)
    assert where["a"] > 70_000
    path = tmp_path / "big.xpdl"
    path.write_text(text, encoding="utf-8")
    result = load_package(path)
    assert result.package is not None
    (process,) = result.package.processes
    lines = {a.id: a.location.line for a in process.activities if a.location}
    # a start tag on two lines is at the line of its ">", as libxml2 says below 65,535
    assert lines == {"a": where["a"], "b": where["b"]}
    assert {t.id: t.location.line for t in process.transitions if t.location} == {
        "t1": where["t1"], "t2": where["t2"]}


def test_the_same_convention_holds_below_65535(tmp_path: Path) -> None:
    text, where = big_spec(10)
    result = parse_bytes(text.encode(), path="small.xpdl")
    assert result.package is not None
    lines = {a.id: a.location.line for a in result.package.processes[0].activities
             if a.location}
    assert lines == {"a": where["a"], "b": where["b"]}


def test_elements_made_while_normalising_keep_lines_past_65535() -> None:
    # XPDL 1.0 Tool -> Task/TaskApplication: the new Task gets the Tool's line; lxml cannot
    # store it (its sourceline is 16 bits), which used to raise OverflowError.
    text, _ = big_spec(70_000, namespace=XPDL10, tool=True)
    result = parse_bytes(text.encode(), path="old.xpdl")
    assert result.package is not None, [str(d) for d in result.diagnostics]
    assert not [d for d in result.diagnostics if d.code == "internal-error"]


def test_outside_a_build_lines_past_65535_are_unknown_not_guessed() -> None:
    data = b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">' + b"\n" * 70000 + b"<X/></Package>"
    outcome = read_tree(data, path="long.xpdl")
    assert line_of(outcome.root) == 1
    assert line_of(outcome.root[0]) is None          # libxml2's guess is not passed on
    assert outcome.lines[outcome.root[0]] == 70001


def test_validate_reports_an_error_past_line_65535_at_its_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from opspec.cli import main

    text, where = big_spec(70_000)
    path = tmp_path / "big.xpdl"
    path.write_text(text, encoding="utf-8")
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:{where['t2']}: error: Transition 't2'" in out


# ---------------------------------------------------------------- encodings


def test_invalid_utf8_in_a_file_declaring_utf8_is_reported_as_such() -> None:
    data = (b'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="' + XPDL21.encode()
            + b'" Id="p"\n Name="caf\xe9"/>')
    result = parse_bytes(data, path="latin.xpdl")
    assert result.package is not None and result.package.name == "caf\u00e9"
    (warning,) = result.diagnostics
    assert warning.code == "encoding-guessed" and warning.severity is Severity.WARNING
    assert "declares UTF-8 but is not valid UTF-8" in warning.message
    assert "(byte 0xE9)" in warning.message and "line" not in warning.message   # file:3 says it
    assert "declares no other encoding" not in warning.message
    assert warning.location.line == 3


def test_invalid_utf8_without_declaration_says_it_declares_nothing() -> None:
    data = b'<Package xmlns="' + XPDL21.encode() + b'" Id="p" Name="caf\xe9"/>'
    (warning,) = parse_bytes(data, path="latin.xpdl").diagnostics
    assert "declares no other encoding" in warning.message and "(byte 0xE9)" in warning.message
    assert warning.location.line == 1 and "line" not in warning.message


# ---------------------------------------------------------------- pipes, devices, folders


def test_a_fifo_is_refused_at_once_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "spec.xpdl"
    os.mkfifo(fifo)
    outcome: list[object] = []
    reader = threading.Thread(target=lambda: outcome.append(load_package(fifo)), daemon=True)
    reader.start()
    reader.join(10)
    if reader.is_alive():  # pragma: no cover - the bug: unblock the thread, then fail
        with open(fifo, "wb"):
            pass
        pytest.fail("reading a FIFO blocked")
    (result,) = outcome
    (diagnostic,) = result.diagnostics  # type: ignore[attr-defined]
    assert diagnostic.code == "io-error"
    assert "named pipe (FIFO), not a regular file" in diagnostic.message


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null"])
def test_a_device_is_refused(device: str) -> None:
    if not Path(device).exists():
        pytest.skip(f"no {device}")
    with pytest.raises(XmlReadError) as caught:
        read_file(device)
    assert caught.value.code == "io-error"
    assert "character device, not a regular file" in caught.value.message


def test_not_a_file_names_what_the_path_is(tmp_path: Path) -> None:
    fifo = tmp_path / "p"
    os.mkfifo(fifo)
    regular = tmp_path / "f.xpdl"
    regular.write_text("<x/>")
    link = tmp_path / "link.xpdl"
    link.symlink_to(regular)
    assert not_a_file(regular) is None and not_a_file(link) is None
    assert not_a_file(tmp_path) == "it is a folder"
    assert not_a_file(tmp_path / "missing") == "it does not exist"
    assert "FIFO" in str(not_a_file(fifo))
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


# ---------------------------------------------------------------- ExternalPackage confinement


def package_with_external(href: str, *, subflow_ref: str | None = None) -> str:
    call = ""
    if subflow_ref is not None:
        call = ('<WorkflowProcesses><WorkflowProcess Id="main"><Activities>'
                f'<Activity Id="call"><Implementation><SubFlow Id="helper" PackageRef="{subflow_ref}"/>'
                "</Implementation></Activity></Activities></WorkflowProcess></WorkflowProcesses>")
    return (f'<Package xmlns="{XPDL21}" Id="m">\n<ExternalPackages>\n'
            f'<ExternalPackage Id="lib" href="{href}"/>\n</ExternalPackages>{call}</Package>')


LIB = f'<Package xmlns="{XPDL21}" Id="lib"><WorkflowProcesses><WorkflowProcess Id="helper"/></WorkflowProcesses></Package>'


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """``outside/lib.xpdl`` beside ``spec/`` (the spec's folder, with ``sub/``)."""
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "lib.xpdl").write_text(LIB)
    (tmp_path / "spec" / "sub").mkdir(parents=True)
    return tmp_path


@pytest.mark.parametrize("href", ["/etc/passwd", "../../../../../../etc/passwd",
                                  "../outside/lib.xpdl"])
def test_external_package_outside_the_spec_folder_is_refused(tree: Path, href: str) -> None:
    main = tree / "spec" / "main.xpdl"
    main.write_text(package_with_external(href))
    result = load_package(main)
    (error,) = result.errors
    assert error.code == "external-package-outside"
    assert f"ExternalPackage {href!r} leads outside the spec's folder" in error.message
    assert "OPSPEC_EXTERNAL_PATH" in error.hint
    assert error.location.line == 3
    assert set(result.packages) == {"m"}            # nothing was read


def test_a_link_leading_out_of_the_tree_is_refused(tree: Path) -> None:
    (tree / "spec" / "lib.xpdl").symlink_to(tree / "outside" / "lib.xpdl")
    main = tree / "spec" / "main.xpdl"
    main.write_text(package_with_external("lib.xpdl"))
    (error,) = load_package(main).errors
    assert error.code == "external-package-outside"
    assert f"which is {tree / 'outside' / 'lib.xpdl'}" in error.message


def test_external_packages_below_and_within_the_tree_resolve(tree: Path) -> None:
    (tree / "spec" / "lib.xpdl").write_text(LIB)
    (tree / "spec" / "sub" / "nested.xpdl").write_text(
        package_with_external("../lib.xpdl").replace('Id="m"', 'Id="nested"'))
    main = tree / "spec" / "main.xpdl"
    main.write_text(package_with_external("sub/nested.xpdl").replace('Id="lib"', 'Id="nested"', 1))
    result = load_package(main)
    assert result.ok, [str(d) for d in result.diagnostics]
    assert set(result.packages) == {"m", "nested", "lib"}


def test_the_documented_variable_allows_another_folder(
        tree: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    main = tree / "spec" / "main.xpdl"
    main.write_text(package_with_external("../outside/lib.xpdl", subflow_ref="lib"))
    monkeypatch.setenv("OPSPEC_EXTERNAL_PATH", str(tree / "outside"))
    result = load_package(main)
    assert result.ok, [str(d) for d in result.diagnostics]
    assert set(result.packages) == {"m", "lib"}


def test_a_subflow_package_ref_outside_the_tree_is_refused(tree: Path) -> None:
    main = tree / "spec" / "main.xpdl"
    main.write_text(f'<Package xmlns="{XPDL21}" Id="m"><WorkflowProcesses>'
                    '<WorkflowProcess Id="main"><Activities><Activity Id="call"><Implementation>'
                    '<SubFlow Id="helper" PackageRef="../outside/lib.xpdl"/></Implementation>'
                    "</Activity></Activities></WorkflowProcess></WorkflowProcesses></Package>")
    result = load_package(main)
    codes = [d.code for d in result.errors]
    assert codes == ["external-package-outside"], [str(d) for d in result.diagnostics]
    assert set(result.packages) == {"m"}


def test_validate_refuses_an_external_package_outside_in_one_line(
        tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from opspec.cli import main as cli

    spec = tree / "spec" / "main.xpdl"
    spec.write_text(package_with_external("/etc/passwd"))
    assert cli(["validate", str(spec)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{spec}:3: error: ExternalPackage '/etc/passwd' leads outside")
    assert "Traceback" not in "\n".join(out)
