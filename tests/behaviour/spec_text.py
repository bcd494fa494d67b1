"""Small SISARL-XPDL packages written as text for the behaviour tests: constructed situations
in the syntax a designer writes (docs/behaviour-specs.md), read by the real reader."""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.xpdl.open_spec import open_spec

__all__ = ["Recorder", "assign", "builtin", "compiled", "field", "process", "task"]


def field(fid: str, kind: str, initial: str) -> str:
    return (f'<DataField Id="{fid}"><DataType><BasicType Type="{kind}"/></DataType>'
            f"<InitialValue>{initial}</InitialValue></DataField>")


def assign(aid: str, *pairs: tuple[str, str], seconds: float | None = None) -> str:
    """An activity assigning ``target = expression`` pairs (taking ``seconds`` if given)."""
    body = "".join(f"<Assignment><Target>{t}</Target><Expression>{e}</Expression></Assignment>"
                   for t, e in pairs)
    takes = ("" if seconds is None else
             '<ExtendedAttributes><ExtendedAttribute Name="opspec:Duration" '
             f'Value="ConstantParameter({seconds})"/></ExtendedAttributes>')
    return (f'<Activity Id="{aid}"><Implementation><No/></Implementation>{takes}'
            f"<Assignments>{body}</Assignments></Activity>")


def builtin(aid: str, xml: str) -> str:
    return (f'<Activity Id="{aid}"><Implementation><No/></Implementation><ExtendedAttributes>'
            f'<ExtendedAttribute Name="opspec:BuiltIn">{xml}</ExtendedAttribute>'
            f"</ExtendedAttributes></Activity>")


def task(aid: str, app: str) -> str:
    return (f'<Activity Id="{aid}"><Implementation><Task><TaskApplication Id="{app}"/></Task>'
            f"</Implementation></Activity>")


def process(pid: str, activities: Sequence[str], *, fields: Sequence[str] = (),
            **directives: str) -> str:
    """A straight-line workflow of ``activities`` (in order) with ``opspec:`` directives."""
    ids = [a.split('Id="', 1)[1].split('"', 1)[0] for a in activities]
    transitions = "".join(f'<Transition Id="{pid}_t{n}" From="{a}" To="{b}"/>'
                          for n, (a, b) in enumerate(itertools.pairwise(ids)))
    attrs = "".join(f'<ExtendedAttribute Name="opspec:{k}" Value="{v}"/>'
                    for k, v in directives.items())
    data = f"<DataFields>{''.join(fields)}</DataFields>" if fields else ""
    return (f'<WorkflowProcess Id="{pid}"><ProcessHeader/>{data}<Activities>'
            f"{''.join(activities)}</Activities><Transitions>{transitions}</Transitions>"
            f"<ExtendedAttributes>{attrs}</ExtendedAttributes></WorkflowProcess>")


def compiled(tmp_path: Path, processes: Sequence[str], *, fields: Sequence[str] = (),
             applications: Sequence[str] = (), package_attributes: str = "",
             name: str = "situation") -> CompiledPackage:
    apps = "".join(f'<Application Id="{a}"/>' for a in applications)
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" xmlns:opspec="urn:opspec:sisarl:1"
         Id="{name}" Name="{name}">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion></PackageHeader>
  {f"<Applications>{apps}</Applications>" if apps else ""}
  {f"<DataFields>{''.join(fields)}</DataFields>" if fields else ""}
  <WorkflowProcesses>{''.join(processes)}</WorkflowProcesses>
  {f"<ExtendedAttributes>{package_attributes}</ExtendedAttributes>"
   if package_attributes else ""}
</Package>
"""
    path = tmp_path / f"{name}.xpdl"
    path.write_text(text, encoding="utf-8")
    return compile_package(open_spec(path))


class Recorder:
    """A device performer that records ``(time, data[key])`` for each application it serves
    and completes the work item at once."""

    def __init__(self, applications: Sequence[str], key: str) -> None:
        self.applications: dict[str, None] = dict.fromkeys(applications)
        self.key = key
        self.seen: list[tuple[float, Any]] = []
        self._session: PerformerSession | None = None

    def attach(self, session: PerformerSession) -> None:
        self._session = session

    def offer(self, item: WorkItem) -> None:
        assert self._session is not None
        self.seen.append((round(self._session.now, 6), _get(item.data, self.key)))
        self._session.complete(item, None)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """Nothing pending."""


def _get(data: Mapping[str, Any], key: str) -> Any:
    return data.get(key)
