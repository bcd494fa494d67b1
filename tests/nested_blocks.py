"""An XPDL package whose blocks nest deeply: shared by the tests of what validate, check, run and
compile say of it (tests/nothing_lost, tests/validate)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["nested_blocks"]


def nested_blocks(path: Path, depth: int, *, cycle: bool = False) -> Path:
    """A process whose BlockActivity's activity set holds a BlockActivity… ``depth`` deep,
    or (``cycle``) whose last set's block refers back to the first set."""
    sets = []
    for i in range(1, depth + 1):
        target = 1 if cycle and i == depth else i + 1
        inner = (f'<Activity Id="b{i + 1}"><BlockActivity ActivitySetId="s{target}"/>'
                 "</Activity>" if i < depth or cycle else
                 '<Activity Id="leaf"><Implementation><No/></Implementation></Activity>')
        sets.append(f'<ActivitySet Id="s{i}"><Activities>{inner}</Activities></ActivitySet>')
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="deep" Name="deep">\n'
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>"
        "<Created>2026-01-01</Created></PackageHeader>\n"
        '<WorkflowProcesses><WorkflowProcess Id="p"><ProcessHeader/>\n'
        f"<ActivitySets>{''.join(sets)}</ActivitySets>\n"
        '<Activities><Activity Id="b1"><BlockActivity ActivitySetId="s1"/></Activity>'
        "</Activities>\n</WorkflowProcess></WorkflowProcesses></Package>\n", encoding="utf-8")
    return path
