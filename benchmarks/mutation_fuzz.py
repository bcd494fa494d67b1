"""Seeded mutation fuzzing of real specs through ``opspec validate`` and ``opspec run``.

Run: ``python benchmarks/mutation_fuzz.py [--seed 1] [--per-operator 2] [--jobs 2]
[--timeout 30] [--out /tmp/fuzz.jsonl] [FILE ...]`` (default files: specs/*.xpdl,
specs/*.bpmn, the shared XPDL corpus, and the BPMN files under tests/).

Each file gets ``--per-operator`` mutants of each operator of ``spec_mutations`` (the damage
a modeller or a hand editor does: a deleted element or attribute, a duplicated id, a
reference to a missing or wrong-kind id, an emptied condition or timer, a non-number where a
number goes, a subflow calling its own process, a start and an end event swapped, a gateway
with no outgoing flow, a dropped namespace, a truncated file, a changed encoding). A mutant
is written beside links to its original's siblings (its user model, world file, called
files) and given to ``opspec validate MUTANT`` and then ``opspec run MUTANT --days 1``, each
in a forked process of this one (opspec imported once: ``opspec.cli.main`` as the console
script calls it) with a timeout.

An outcome is a finding when it is

- ``traceback``: an internal error (exit 70) or a Python traceback on either stream;
- ``hang``: the command did not end within the timeout;
- ``bad-exit``: an exit status other than 0, 1, 2 (killed by a signal included);
- ``no-location``: an error (``error:`` line, or the one-line refusal of ``run``) that does
  not name the mutant ``file:line``;
- ``validate-ok-run-refuses``: validate exits 0 and run refuses the spec before it starts
  (validate = run: what run refuses, validate reports);
- ``validate-refuses-run-ok``: validate exits 1 and run exits 0;
- ``odd-message``: a message leaking Python (``None``, ``{http://…}`` names, ``object at``);
- ``untrue-message``: a message of a kind found untrue by reading them (``UNTRUE``).

It prints the counts by class and by operator and the distinct messages of each class
(numbers, quoted names and paths folded), and writes one JSON line a mutant to ``--out``.
It asserts nothing; it is not run by CI (a full run takes tens of minutes).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import re
import resource
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from spec_mutations import OPERATORS, mutate

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "corpus" / "xpdl"
if not CORPUS.is_dir():
    CORPUS = Path("/work/shared/corpus/xpdl")


def default_files() -> list[Path]:
    files = [*sorted((ROOT / "specs").glob("*.xpdl")), *sorted((ROOT / "specs").glob("*.bpmn"))]
    files += sorted(CORPUS.rglob("*.xpdl")) if CORPUS.is_dir() else []
    files += sorted((ROOT / "tests").rglob("*.bpmn"))
    return files


def _child(argv: list[str], stem: str) -> None:
    """In the forked process: run the command with its streams in files, exit its status."""
    from opspec.cli import main

    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    for fd, suffix in ((1, ".out"), (2, ".err")):
        os.dup2(os.open(stem + suffix, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    status = 99
    try:
        status = main(argv)
    except SystemExit as stop:        # argparse's refusals
        status = stop.code if isinstance(stop.code, int) else 2
    except BaseException:             # noqa: BLE001 - a traceback main let through
        import traceback
        traceback.print_exc()
        status = 98
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)


class Runner:
    """At most ``jobs`` forked commands at a time, each killed past ``timeout`` seconds."""

    def __init__(self, jobs: int, timeout: float) -> None:
        self.jobs, self.timeout = jobs, timeout
        self.running: dict[int, tuple[float, str, dict]] = {}

    def start(self, argv: list[str], stem: str, record: dict) -> None:
        while len(self.running) >= self.jobs:
            self.reap()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            _child(argv, stem)
        self.running[pid] = (time.monotonic() + self.timeout, stem, record)

    def reap(self, block: bool = True) -> None:
        while self.running:
            pid, status = os.waitpid(-1, os.WNOHANG)
            if pid:
                _, stem, record = self.running.pop(pid)
                record["rc"] = os.waitstatus_to_exitcode(status)
                Path(f"{stem}.rc").write_text(str(record["rc"]))
                _collect(stem, record)
                return
            now = time.monotonic()
            for pid, (deadline, stem, record) in list(self.running.items()):
                if now > deadline:
                    os.kill(pid, signal.SIGKILL)
                    os.waitpid(pid, 0)
                    self.running.pop(pid)
                    record["rc"] = "timeout"
                    Path(f"{stem}.rc").write_text("timeout")
                    _collect(stem, record)
                    return
            if not block:
                return
            time.sleep(0.02)

    def drain(self) -> None:
        while self.running:
            self.reap()


def _collect(stem: str, record: dict) -> None:
    for suffix in ("out", "err"):
        path = Path(f"{stem}.{suffix}")
        record[suffix] = path.read_text("utf-8", "replace") if path.exists() else ""


LOCATED = r"{name}:\d+"
ODD = re.compile(r"(?<!Trigger )\bNone\b|\{https?://|object at 0x|<Element |\bKeyError\b|\bAttributeError\b"
                 r"|\bTypeError\b|\bValueError\b|\bIndexError\b")


# messages found untrue by reading the harness's output (each pattern is one class of them,
# fixed): a file of XML text called binary; libxml2's words for an encoding declaration the file
# cannot be in, with "fix the XML syntax"; an ISO 8601 duration, misspelt, read as data fields;
# a flow node of the flow's own level, or no flow node, said to be "of another process"
UNTRUE = re.compile(r"a binary file \(not text\)|Unsupported encoding|Blank needed here"
                    r"|(deadline|timer) of activity .* reads '(P|-?P(T|\d+[YMWDHS])[\dYMWDTHS.,]*|R\d*)', "
                    r"which is not a data"
                    r"|bpmn:(dataObject|message|error|signal|property|dataStoreReference|"
                    r"textAnnotation)\b[^;]* of another process")


def _unquoted(line: str) -> str:
    """``line`` without what it quotes (a spec's own text may say None or TypeError)."""
    return re.sub(r"'[^']*'|\"[^\"]*\"|\([^()]*\)", "", line)


OTHER_LEVEL = re.compile(r"sequence flow '([^']*)': \w+ '([^']*)' is no flow node of .*; it "
                         r"is a bpmn:\w+ \(line \d+\) of another process or sub-process")


def _same_level_said_other(line: str, name: str, rec: dict) -> bool:
    """A flow's end said to be "of another process or sub-process" while it is beside the
    flow (the mutant read again to see)."""
    match = OTHER_LEVEL.search(line)
    spec = rec.get("spec")
    if match is None or not spec:
        return False
    from lxml import etree
    try:
        root = etree.parse(spec, etree.XMLParser(resolve_entities=False, no_network=True)
                           ).getroot()
    except (OSError, etree.XMLSyntaxError):
        return False
    found = {e.get("id"): e for e in root.iter() if isinstance(e.tag, str) and e.get("id")}
    flow, end = found.get(match.group(1)), found.get(match.group(2))
    return flow is not None and end is not None and flow.getparent() is end.getparent()


def classify(name: str, validate: dict, run: dict) -> list[str]:
    """The finding classes of one mutant's two outcomes (empty: none)."""
    found: list[str] = []
    located = re.compile(LOCATED.format(name=re.escape(name)))
    for which, rec in (("validate", validate), ("run", run)):
        text = rec["out"] + rec["err"]
        if rec["rc"] == "timeout":
            found.append(f"hang:{which}")
            continue
        if rec["rc"] == 70 or "Traceback (most recent call last)" in text \
                or "internal error" in text:
            found.append(f"traceback:{which}")
        elif rec["rc"] not in (0, 1, 2):
            found.append(f"bad-exit:{which}")
        errors = [line for line in text.splitlines() if ": error:" in line]
        refused = which == "run" and rec["rc"] in (1, 2) and "ended at" not in rec["out"]
        if refused:   # its refusal: the lines of its own that are no warning
            errors += [line for line in rec["err"].splitlines()
                       if line.startswith("opspec run:") and ": warning:" not in line][:1]
        if any(not located.search(line) for line in errors) and rec["rc"] != 70:
            found.append(f"no-location:{which}")
        if any(ODD.search(_unquoted(line)) for line in (*rec["err"].splitlines(), *errors)):
            found.append(f"odd-message:{which}")
        if any(UNTRUE.search(line) or _same_level_said_other(line, name, rec)
               for line in errors):
            found.append(f"untrue-message:{which}")
    started = "ended at" in run["out"]
    if validate["rc"] == 0 and run["rc"] in (1, 2) and not started:
        found.append("validate-ok-run-refuses")
    if validate["rc"] == 1 and run["rc"] == 0:
        found.append("validate-refuses-run-ok")
    return found


def signature(text: str, name: str) -> str:
    """A message with what varies between mutants folded, to group findings by class."""
    text = text.replace(name, "FILE")
    text = re.sub(r"'[^']*'|\"[^\"]*\"", "'…'", text)
    text = re.sub(r"/\S+", "PATH", text)
    text = re.sub(r"\d+(\.\d+)?", "N", text)
    return text[:220]


def first_problem(rec: dict) -> str:
    """The line that best says what went wrong in one outcome."""
    lines = (rec["err"] + "\n" + rec["out"]).splitlines()
    for wanted in ("internal error", "Traceback", ": error:", ""):
        for line in lines:
            if wanted == "Traceback" and wanted in line:
                return rec["err"].strip().splitlines()[-1]
            if wanted in line and line.startswith("opspec") | (wanted != "") \
                    and ": warning:" not in line and line.strip():
                return line.strip()
    return lines[-1] if lines else ""


def _link_siblings(original: Path, folder: Path) -> None:
    for sibling in original.parent.iterdir():
        if sibling.name != original.name and sibling.is_file():
            try:
                os.symlink(sibling, folder / sibling.name)
            except OSError:
                pass


def plan(files: list[Path], operators: list[str], args: argparse.Namespace):
    """Every mutant of the run, in order: (original, operator, label, bytes); the same for the
    same arguments, so a run's folder can be classified again, or its mutants rerun."""
    for original in files:
        data = original.read_bytes()
        steps = [("original", -1)] if args.originals else []
        chosen = operators
        if args.sample:
            chosen = random.Random(f"{args.seed}:{original.name}").sample(
                operators, min(args.sample, len(operators)))
        steps += [(op, i) for op in chosen for i in range(args.per_operator)]
        for operator, i in steps:
            if operator == "original":
                yield original, operator, "original", data
                continue
            made = mutate(data, operator, random.Random(
                f"{args.seed}:{original.name}:{operator}:{i}"))
            if made is not None:
                yield original, operator, made[0], made[1]


def _rc_of(stem: Path, record: dict) -> int | str:
    """The exit status a run wrote, or (a run stopped before it wrote them) the one its
    output shows: 70 an internal error, 1 an error said, else 0."""
    written = Path(f"{stem}.rc")
    if written.exists():
        text = written.read_text().strip()
        return int(text) if text.lstrip("-").isdigit() else text
    text = record["out"] + record["err"]
    if "internal error" in text or "Traceback" in text:
        return 70
    if ": error:" in text or (stem.name == "run" and "ended at" not in record["out"]):
        return 1
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--per-operator", type=int, default=2)
    parser.add_argument("--operators", default=",".join(OPERATORS))
    parser.add_argument("--sample", type=int, default=0,
                        help="give each file only this many of the operators, drawn from "
                             "the seed (0: all)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=30.0)
    parser.add_argument("--days", default="1")
    parser.add_argument("--out", type=Path, default=Path("/tmp/mutation_fuzz.jsonl"))
    parser.add_argument("--keep", type=Path, help="keep the mutants in this folder")
    parser.add_argument("--originals", action="store_true", help="also run each original")
    parser.add_argument("--limit-mutants", type=int, help="stop after this many mutants")
    parser.add_argument("--classify", type=Path, metavar="DIR",
                        help="run nothing: classify the outcomes an earlier run (--keep DIR, "
                             "same arguments) left in DIR")
    args = parser.parse_args()
    files = args.files or default_files()
    operators = args.operators.split(",")

    import opspec.cli
    import opspec.commands.run
    import opspec.commands.validate
    opspec.cli.build_parser("run")
    opspec.cli.build_parser("validate")

    work = args.classify or args.keep or Path(tempfile.mkdtemp(prefix="opspec-fuzz-"))
    work.mkdir(parents=True, exist_ok=True)
    runner = Runner(args.jobs, args.timeout)
    mutants: list[dict] = []
    started = time.monotonic()
    for original, operator, label, body in plan(files, operators, args):
        if args.limit_mutants is not None and len(mutants) >= args.limit_mutants:
            break
        folder = work / f"m{len(mutants):05d}"
        record = {"id": len(mutants), "file": str(original), "operator": operator,
                  "mutation": label, "mutant": str(folder / original.name),
                  "validate": {}, "run": {}}
        mutants.append(record)
        if args.classify is not None:     # outcomes a run left in that folder
            for which in ("validate", "run"):
                _collect(str(folder / which), record[which])
                record[which]["rc"] = _rc_of(folder / which, record[which])
            continue
        folder.mkdir()
        _link_siblings(original, folder)
        spec = folder / original.name
        spec.write_bytes(body)
        runner.start(["validate", str(spec)], str(folder / "validate"), record["validate"])
        runner.start(["run", str(spec), "--days", args.days], str(folder / "run"),
                     record["run"])
    runner.drain()
    elapsed = time.monotonic() - started

    by_class: collections.Counter[str] = collections.Counter()
    by_operator: dict[str, collections.Counter[str]] = collections.defaultdict(
        collections.Counter)
    messages: dict[str, collections.Counter[str]] = collections.defaultdict(
        collections.Counter)
    examples: dict[tuple[str, str], str] = {}
    with args.out.open("w") as out:
        for record in mutants:
            name = Path(record["mutant"]).name
            for which in ("validate", "run"):
                record[which]["spec"] = record["mutant"]
            record["findings"] = classify(name, record["validate"], record["run"])
            by_operator[record["operator"]]["mutants"] += 1
            for finding in record["findings"] or ["clean"]:
                by_class[finding] += 1
                by_operator[record["operator"]][finding] += 1
                if finding != "clean":
                    which = "run" if finding.endswith("run") or "run-" in finding else "validate"
                    sig = signature(first_problem(record[which]), name)
                    messages[finding][sig] += 1
                    examples.setdefault((finding, sig), f"{record['mutant']} "
                                        f"({record['mutation']})")
            out.write(json.dumps(record) + "\n")
    if args.keep is None and args.classify is None:
        shutil.rmtree(work, ignore_errors=True)

    print(f"{len(files)} files, {len(mutants)} mutants, {elapsed:.0f} s")
    for finding, count in sorted(by_class.items()):
        print(f"  {finding:30} {count}")
    print("by operator:")
    for operator, counts in sorted(by_operator.items()):
        print(f"  {operator:22} " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for finding, sigs in sorted(messages.items()):
        print(f"\n== {finding}: {len(sigs)} distinct")
        for sig, count in sigs.most_common(25):
            print(f"  {count:4}  {sig}\n        e.g. {examples[(finding, sig)]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
