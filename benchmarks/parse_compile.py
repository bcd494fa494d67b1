"""Parse + compile benchmark: loading XPDL against loading the compiled ``.wfs``.

Run: ``.venv/bin/python benchmarks/parse_compile.py [--repeats 7] [--target-kb 1024]``.

Two inputs: the largest corpus file and a generated package of about ``--target-kb`` KiB
(written with :func:`opspec.xpdl.writer.write_xpdl`: processes of tasks, XOR splits with
conditions, assignments, deadlines and extended attributes). For each it times, in the same
run, the median of ``--repeats`` runs of

- XPDL load (``opspec.xpdl.loader.load_package``: read, parse, build the model, resolve),
- compile (``opspec.model.codec.write_wfs``: model -> JSON -> file),
- ``.wfs`` load (``opspec.model.codec.read_wfs``), with the share of it spent in ``json.loads``,

and prints the ratio XPDL load / .wfs load. It prints; it asserts nothing.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from opspec.model import (
    Activity,
    Assignment,
    BasicKind,
    BasicType,
    Condition,
    ConditionKind,
    DataField,
    Deadline,
    Event,
    EventPosition,
    ExtendedAttribute,
    GatewayType,
    Join,
    Package,
    Participant,
    Route,
    Split,
    Task,
    TaskApplication,
    TaskKind,
    Transition,
    WorkflowProcess,
)
from opspec.model.codec import read_wfs, write_wfs
from opspec.xpdl.loader import load_package
from opspec.xpdl.writer import write_xpdl

CORPUS = Path("/work/shared/corpus/xpdl")


def _median_seconds(action: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _process(index: int, branches: int) -> WorkflowProcess:
    """start -> work -> XOR split into ``branches`` conditional tasks -> XOR join -> end."""
    p = f"proc{index}"
    activities = [
        Activity(id=f"{p}_start", body=Event(position=EventPosition.START), performers=("dev",)),
        Activity(id=f"{p}_work", name="Do the work", performers=("dev",),
                 body=Task(kind=TaskKind.APPLICATION,
                           applications=(TaskApplication(application="act"),)),
                 deadlines=(Deadline(duration_text="PT30S", exception_name="late"),),
                 assignments=(Assignment(target="n", text="n + 1"),),
                 extended_attributes=(ExtendedAttribute(name="opspec:AutoRun", value="true"),
                                      ExtendedAttribute(name="Vendor", value="x" * 20))),
    ]
    split_refs = tuple(f"{p}_s{b}" for b in range(branches))
    activities.append(Activity(id=f"{p}_choose", body=Route(gateway=GatewayType.XOR),
                               split=Split(type=GatewayType.XOR, transition_refs=split_refs)))
    transitions = [Transition(id=f"{p}_t0", source=f"{p}_start", target=f"{p}_work"),
                   Transition(id=f"{p}_t1", source=f"{p}_work", target=f"{p}_choose")]
    for b in range(branches):
        activities.append(Activity(id=f"{p}_b{b}", name=f"Branch {b}", performers=("dev",),
                                   assignments=(Assignment(target="status",
                                                           text=f'"branch {b}"'),)))
        condition = (Condition(kind=ConditionKind.OTHERWISE) if b == branches - 1 else
                     Condition(kind=ConditionKind.CONDITION,
                               text=f'n < {b * 10} && status != "done{b}"'))
        transitions.append(Transition(id=f"{p}_s{b}", source=f"{p}_choose",
                                      target=f"{p}_b{b}", condition=condition))
        transitions.append(Transition(id=f"{p}_m{b}", source=f"{p}_b{b}", target=f"{p}_merge"))
    activities.append(Activity(id=f"{p}_merge", body=Route(gateway=GatewayType.XOR),
                               join=Join(type=GatewayType.XOR)))
    activities.append(Activity(id=f"{p}_end", body=Event(position=EventPosition.END)))
    transitions.append(Transition(id=f"{p}_t2", source=f"{p}_merge", target=f"{p}_end"))
    return WorkflowProcess(
        id=p, name=f"Generated process {index}", activities=tuple(activities),
        transitions=tuple(transitions),
        data_fields=(DataField(id="n", type=BasicType(kind=BasicKind.INTEGER), initial_value="0"),
                     DataField(id="status", type=BasicType(kind=BasicKind.STRING),
                               initial_value='""')))


def generated_xpdl(target_bytes: int) -> bytes:
    """XPDL 2.1 text of a generated package of about ``target_bytes``."""
    def package(count: int) -> Package:
        return Package(id="generated", name="Generated benchmark package",
                       participants=(Participant(id="dev"),),
                       processes=tuple(_process(i, 6) for i in range(count)))

    per_process = len(write_xpdl(package(10))) / 10
    return write_xpdl(package(max(1, round(target_bytes / per_process))))


def bench(label: str, source: Path, work: Path, repeats: int) -> None:
    wfs = work / f"{source.stem}.wfs"
    result = load_package(source)
    assert result.package is not None, [str(d) for d in result.diagnostics]
    package = result.package
    t_xpdl = _median_seconds(lambda: load_package(source), repeats)
    t_compile = _median_seconds(lambda: write_wfs(package, wfs), repeats)
    t_wfs = _median_seconds(lambda: read_wfs(wfs), repeats)
    raw = wfs.read_bytes()
    t_json = _median_seconds(lambda: json.loads(raw), repeats)
    assert read_wfs(wfs) == package   # the benchmark measures a correct round trip
    activities = sum(len(p.all_activities()) for p in package.processes)
    print(f"{label}: {source.name}")
    print(f"  size: XPDL {source.stat().st_size / 1024:8.1f} KiB, .wfs {len(raw) / 1024:8.1f} KiB;"
          f" {len(package.processes)} processes, {activities} activities")
    print(f"  XPDL load   {t_xpdl * 1e3:9.2f} ms")
    print(f"  compile     {t_compile * 1e3:9.2f} ms  (dump + atomic write)")
    print(f"  .wfs load   {t_wfs * 1e3:9.2f} ms  (json.loads {t_json * 1e3:.2f} ms = "
          f"{100 * t_json / t_wfs:.0f} %)")
    print(f"  ratio XPDL load / .wfs load = {t_xpdl / t_wfs:.2f}x")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--target-kb", type=int, default=1024)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        largest = max(CORPUS.glob("*.xpdl"), key=lambda p: p.stat().st_size)
        bench("largest corpus file", largest, work, args.repeats)
        generated = work / "generated.xpdl"
        generated.write_bytes(generated_xpdl(args.target_kb * 1024))
        bench(f"generated package (~{args.target_kb} KiB)", generated, work, args.repeats)
    print(f"(median of {args.repeats} runs each; Python {sys.version.split()[0]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
