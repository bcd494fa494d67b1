"""The traces an evaluation exports besides its results (``--export``): the formats and
the file each writes in the output folder, the streaming writer of each, and the estimate of
their size made before the run (a disk too small, or a file past the trace cap, stops the
run before it starts)."""
from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError

__all__ = ["EXPORTS", "EXPORT_FILES", "export_estimate", "export_formats", "export_writer",
           "log_name", "trace_writers"]

EXPORTS = ("xes", "jsonl", "ocel")
#: the file each export format writes, in the output folder
EXPORT_FILES = {"xes": "traces.xes", "jsonl": "traces.jsonl", "ocel": "traces.jsonocel"}


def export_formats(values: list[str]) -> tuple[str, ...]:
    """The formats ``--export`` names (repeated or comma-separated), each once, in the order
    given; an unknown one is refused."""
    formats: list[str] = []
    for value in values:
        for part in value.split(","):
            fmt = part.strip().lower()
            if fmt not in EXPORTS:
                raise EvaluationError(f"--export {part!r} is not a known format",
                                      hint=f"choose from: {', '.join(EXPORTS)}")
            if fmt not in formats:
                formats.append(fmt)
    return tuple(formats)


def export_writer(fmt: str, path: Path, plan: Any) -> Any:
    """The streaming writer of one export format."""
    from opspec.evaluation.exporters import JsonlTraceWriter, XesWriter

    # one key in both logs (XES keys hold no spaces, and a JSON reader looks up the same name)
    attrs: dict[str, Any] = {"spec": plan.design("A").spec, "seed": plan.seed,
                             "case_notion": plan.case}
    if fmt == "jsonl":
        return JsonlTraceWriter(path, log_attributes=attrs)
    from opspec.commands._spec import load_any_spec
    from opspec.engine.compiled import compile_package
    from opspec.engine.lane_labels import lane_labels
    from opspec.engine.lanes import user_lane
    from opspec.evaluation.ocel import OcelWriter, people_of

    package = load_any_spec(plan.design("A").spec)
    compiled = compile_package(package)
    # org:group names a lane as the timeline does: its name, its id where it has none
    lanes = lane_labels(compiled).names
    if fmt == "xes":
        # the log's concept:name is the name of the process executed (XES Concept extension:
        # "for logs, the name attribute may store the name of the process having been
        # executed"): the spec's, which a process-mining tool lists the log by
        return XesWriter(path, log_attributes={"concept:name": log_name(plan, package),
                                               **attrs}, lane_names=lanes)
    people = people_of(package, user_lane(compiled).bind_names, compiled)
    return OcelWriter(path, people=people, lane_names=lanes)


def log_name(plan: Any, package: Any) -> str:
    """The XES log's name: the spec's (its package's name, else its id); with --compare,
    both specs' (``A compared with B``), for the log holds the cases of both designs."""
    from opspec.commands._spec import load_any_spec

    names = [package.label]
    for design in plan.designs:
        if design.spec != plan.design("A").spec:
            label = load_any_spec(design.spec).label
            if label not in names:
                names.append(label)
    return " compared with ".join(names)


def trace_writers(stack: contextlib.ExitStack, folder: Path, plan: Any) -> Any:
    """What writes one replication's trace into every export file of ``plan`` in ``folder``
    (each writer entered on ``stack``: closing it finishes the files); ``None`` without
    exports."""
    if not plan.export:
        return None
    from opspec.engine.trace import TraceEvent
    from opspec.evaluation.cases import split_cases

    # a resumed run simulates the stored users again for their traces (run_evaluation's
    # retrace), so each file is written whole again; the interrupted run's .partial goes
    cased: list[Any] = []
    whole: list[Any] = []
    for fmt in plan.export:
        writer = stack.enter_context(export_writer(fmt, folder / EXPORT_FILES[fmt], plan))
        (whole if fmt == "ocel" else cased).append(writer)

    def write(record: Any) -> None:
        events = [TraceEvent.from_json(e) for e in record.trace]
        base = f"{record.design}/{record.user}"
        attributes = {"design": record.design, "user": record.user}
        if cased:
            for suffix, group in split_cases(events, plan.case):
                case_id = base if suffix is None else f"{base}/{suffix}"
                for writer in cased:
                    writer.add_case(case_id, group, attributes)
        for writer in whole:
            writer.add_case(base, events, attributes)

    return write


def export_estimate(plan: Any, folder: Path, quiet: bool) -> None:
    """Say how large each export will be, before the run: one simulated user-day of user 0
    is exported to a scratch folder and scaled to every user and day. An estimate larger
    than the disk's free space, or than the trace cap, stops here (exit 2) instead of hours
    later."""
    import shutil
    import tempfile

    from opspec.engine.trace_sinks import TRACE_MAX_BYTES_ENV, trace_max_bytes
    from opspec.evaluation.plan import DAY
    from opspec.evaluation.replication import prepare, run_user

    design = plan.designs[0]
    context = prepare(design.spec, design.sha256, plan.user_model, plan.engine,
                      design.parameters, plan.branches or None)
    sample = min(plan.horizon, DAY)
    record = run_user(context, design.label, 0, seed=plan.seed, horizon=sample,
                      keep_trace=True)
    if record.trace is None:
        return
    scale = plan.users * len(plan.designs) * plan.horizon / sample
    sizes: dict[str, float] = {}
    try:
        with tempfile.TemporaryDirectory(prefix="opspec-estimate-") as scratch, \
                contextlib.ExitStack() as stack:
            write = trace_writers(stack, Path(scratch), plan)
            write(record)
            stack.close()
            for fmt in plan.export:
                sizes[fmt] = (Path(scratch) / EXPORT_FILES[fmt]).stat().st_size * scale
    except (OSError, EvaluationError) as error:
        # the scratch folder (the system's temporary folder) is not the output's disk
        if not quiet:
            print(f"opspec evaluate: the size of the export could not be estimated ({error})",
                  file=sys.stderr)
        return
    total = sum(sizes.values())
    span = f"{plan.users:,} user(s) x {plan.days:g} day(s)" + (
        f" x {len(plan.designs)} designs" if len(plan.designs) > 1 else "")
    if not quiet:
        for fmt, size in sizes.items():
            print(f"opspec evaluate: {EXPORT_FILES[fmt]} will be about {_bytes(size)} ({span}; "
                  "estimated from one simulated user-day)", file=sys.stderr)
    cap = trace_max_bytes()
    over = [fmt for fmt, size in sizes.items() if size > cap]
    if over:
        raise EvaluationError(
            f"--export {','.join(over)}: {EXPORT_FILES[over[0]]} would be about "
            f"{_bytes(sizes[over[0]])}, past the trace cap of {_bytes(cap)}",
            hint=f"export fewer users or days, or set {TRACE_MAX_BYTES_ENV} to a larger "
            "number of bytes")
    where = folder
    while not where.exists() and where != where.parent:
        where = where.parent
    free = shutil.disk_usage(where).free
    if total > free:
        raise EvaluationError(
            f"--export needs about {_bytes(total)} in {folder}, and the disk has "
            f"{_bytes(free)} free", hint="free some space, export fewer users or days, or "
            "choose another --out")


def _bytes(size: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if size >= scale:
            return f"{size / scale:.3g} {unit}"
    return f"{size:.0f} bytes"
