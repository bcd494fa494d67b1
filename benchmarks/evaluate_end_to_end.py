"""`opspec evaluate` end to end against the hand-coded baseline, in the same run.

For N users x D days of the medication dispenser (1,000 x 30 by default), each in a fresh
interpreter, in interleaved rounds (baseline, engine alone, evaluate, ... : a load that drifts
hits all alike):

- **baseline**: the hand-coded SimPy model of the same scenario
  (``shared/bench/handcoded_simpy.py`` beside the checkout or a folder above it, or
  ``$OPSPEC_BENCH``);
- **engine alone**: the replications ``opspec evaluate`` runs, and nothing else - every
  user's run of ``opspec.evaluation.replication.run_users`` (spec loaded once, the user model
  drawing, metrics, per-activity counts), results thrown away;
- **evaluate --workers 1**: ``opspec evaluate SPEC --workers 1`` as a user runs it: the same
  replications, the result store (``results.sqlite``), the summaries and the report
  (``report.html`` with its figures);
- **evaluate --workers W** (``--workers 1,2``): the same on W worker processes, for the
  wall-time speed-up (honest only on a machine whose cores are otherwise idle).

CPU time is user + system of the child and of the processes it waited for (its pool's
workers), from ``os.wait4``: what the work costs, steadier than wall time on a busy machine.
Each round prints its ratios against the baseline of the same round; the summary gives their
median and range (goals of issue 31: evaluate --workers 1 at most 1.5x the baseline; workers 2
at least 1.8x faster than 1). The load average before and after is printed with them. For
each ``evaluate --workers W`` it also prints the CPU of its parts - start-up, the evaluate
process storing beside its workers and the workers' own, the tail after the replications,
the report's drawing processes - and from them an estimate of the speed-up of W workers over
1 on W idle cores (``estimated_wall``), which a machine others load cannot show in wall time.

``--instructions`` instead counts, with valgrind's callgrind, the instructions of the baseline,
the engine alone and ``opspec evaluate --workers 1`` (store, summaries and report included)
at ``--users`` x ``--days``, each once (``PYTHONHASHSEED=0``): a measure that the other work
on a shared machine does not move, where CPU seconds of the same command swing by a third
(200 users x 30 days take a few minutes under callgrind).

``--memory 10000,100000`` instead runs ``evaluate --days 1`` for each number of users and
prints the peak and final resident memory of the evaluate process itself (not its workers;
goal: flat from 10,000 to 100,000 users). ``--profile FILE`` also writes a CPU-time cProfile
of one ``evaluate --workers 1`` (``python -m pstats FILE``). The first line says which engine
ran (compiled with mypyc, or from source): run it from the checkout whose engine you measure.

    python benchmarks/evaluate_end_to_end.py [--users 1000] [--days 30] [--rounds 3]
        [--workers 1,2] [--memory 10000,100000] [--instructions] [--profile FILE]
        [--no-bytecode]

Before measuring it writes the bytecode of opspec's modules (``compileall``), as an install
or a first run leaves it on a user's machine; ``--no-bytecode`` skips that (see
``byte_compile``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS_TOML = ROOT / "specs" / "medication_dispenser.users.toml"


def _baseline_script() -> Path | None:
    """``shared/bench/handcoded_simpy.py`` in ``$OPSPEC_BENCH`` or beside a folder above."""
    env = os.environ.get("OPSPEC_BENCH")
    places = [Path(env)] if env else []
    places += [parent / "shared" / "bench" for parent in ROOT.parents]
    return next((p / "handcoded_simpy.py" for p in places
                 if (p / "handcoded_simpy.py").is_file()), None)


# The replications of `opspec evaluate --workers 1`, in the chunks it sends, and nothing else.
_ENGINE = """
import sys
from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import run_users
from opspec.evaluation.runner import chunks
spec, model, users, days, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
plan = {"designs": [{"label": "A", "spec": spec, "sha256": file_digest(spec)}],
        "users": users, "days": days, "seed": seed, "user_model": model, "engine": {},
        "export": []}
done = 0
for chunk in chunks(list(range(users)), 1):
    done += sum(r.status == "done" for r in run_users(plan, "A", chunk))
assert done == users, done
"""

# `opspec evaluate` as the command line runs it, then this process's own memory: its peak
# (ru_maxrss: the run, the summaries and the report) and what it holds at the end.
# Also the CPU of each part (the phases of an estimate of the wall time on idle cores): this
# process before the replications, during them and after them; the processes it waited for
# (the replication workers; the report's drawing processes) until the replications ended and
# after; and of the drawing processes, what they spent before the replications (started with
# the command, they use the cores its start-up leaves idle), from /proc.
_EVALUATE = """
import json, os, resource, sys, time
import opspec.evaluation.runner as runner
from opspec.cli import main

def cpu(who):
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime

def children_cpu():
    total = 0.0
    try:
        for task in os.listdir("/proc/self/task"):
            with open(f"/proc/self/task/{task}/children") as f:
                for pid in f.read().split():
                    with open(f"/proc/{pid}/stat") as stat:
                        fields = stat.read().rsplit(")", 1)[1].split()
                    total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        pass
    return total

# {pid: CPU s} of every live process below this one (the drawing processes the first one
# forked are its children, not this one's)
def descendants_cpu(pid="self"):
    out = {}
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/children") as f:
                for child in f.read().split():
                    with open(f"/proc/{child}/stat") as stat:
                        fields = stat.read().rsplit(")", 1)[1].split()
                    out[child] = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
                    out.update(descendants_cpu(child))
    except OSError:
        pass
    return out

marks = {}
replications = runner.run_evaluation

def timed(*args, **kwargs):
    marks["before"] = cpu(resource.RUSAGE_SELF)
    marks["early"] = children_cpu()
    try:
        return replications(*args, **kwargs)
    finally:
        marks["during"] = cpu(resource.RUSAGE_SELF) - marks["before"]
        marks["workers"] = cpu(resource.RUSAGE_CHILDREN)

runner.run_evaluation = timed

# the tail starts as the last replication is stored: what comes after it (the sample index,
# the summaries, the report's figures asked for ahead of it) runs after the workers, alone
storing = runner.ResultStore.add_many

def add_many(store, records):
    try:
        return storing(store, records)
    finally:
        marks["stored"] = cpu(resource.RUSAGE_SELF)
        below["stored"] = descendants_cpu()

runner.ResultStore.add_many = add_many

# what the drawing processes draw from then until the report is written (the figures asked
# for ahead, beside the index and the summaries) runs on the core the evaluate process
# leaves idle: the processes still there then (the replications' are gone) are theirs
import opspec.evaluation.report as report
writing = report.write_report
below = {}

def write_report(*args, **kwargs):
    marks["report"] = cpu(resource.RUSAGE_SELF)
    then, now = below.get("stored", {}), descendants_cpu()
    marks["beside"] = sum(c - then.get(pid, 0.0) for pid, c in now.items())
    return writing(*args, **kwargs)

report.write_report = write_report
status = main(sys.argv[1:])
marks["after"] = cpu(resource.RUSAGE_SELF) - marks["before"] - marks["during"]
if "stored" in marks:
    tail = marks["before"] + marks["during"] - marks["stored"]
    marks["during"] -= tail
    marks["after"] += tail
    marks["alone"] = marks.pop("report") - marks.pop("stored")
marks["drawing"] = cpu(resource.RUSAGE_CHILDREN) - marks["workers"]
with open("/proc/self/statm") as statm:
    now = int(statm.read().split()[1]) * resource.getpagesize() / 2**20
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print("@@memory " + json.dumps({"peak_mib": peak, "end_mib": now, "cpu": marks}),
      file=sys.stderr)
sys.exit(status)
"""


class Measured:
    """CPU and wall seconds, the stdout and stderr of one child process."""

    def __init__(self, cmd: list[str], cwd: Path | None = None) -> None:
        start = time.perf_counter()
        with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
            child = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=err, text=True)
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = os.waitstatus_to_exitcode(status)
            self.wall = time.perf_counter() - start
            out.seek(0)
            err.seek(0)
            self.stdout, self.stderr = out.read(), err.read()
        if child.returncode != 0:
            sys.exit(f"failed ({child.returncode}): {' '.join(cmd)}\n{self.stderr}")
        self.cpu = usage.ru_utime + usage.ru_stime


def baseline(script: Path, users: int, days: int, seed: int) -> Measured:
    return Measured([sys.executable, str(script), "--users", str(users), "--days", str(days),
                     "--seed", str(seed)], cwd=script.parent)


def baselines_at_once(script: Path, users: int, days: int, seed: int, copies: int) -> float:
    """The wall seconds of ``copies`` baselines started together: what this machine's cores
    give CPU-bound work side by side (on this VM two identical processes at once ran 1.45x to
    2.76x one alone, the cores' speed moving with the host's load), the ceiling of
    ``--workers W`` measured in the same round."""
    start = time.perf_counter()
    children = [subprocess.Popen([sys.executable, str(script), "--users", str(users),
                                  "--days", str(days), "--seed", str(seed)],
                                 cwd=script.parent, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL) for _ in range(copies)]
    for child in children:
        if child.wait() != 0:
            sys.exit(f"failed ({child.returncode}): the baseline, {copies} at once")
    return time.perf_counter() - start


def engine_alone(users: int, days: int, seed: int) -> Measured:
    return Measured([sys.executable, "-c", _ENGINE, str(SPEC), str(USERS_TOML), str(users),
                     str(days), str(seed)], cwd=ROOT)


def estimated_wall(phases: dict[str, float], workers: int) -> float:
    """The wall time of one evaluate on ``workers`` idle cores, from the CPU of its parts:
    start-up alone, the replications' workers and this process's storing shared over the
    cores, this process's tail (from the last replication stored: the sample index, the
    summaries, the tables), the figures' processes shared over the cores. An upper bound
    where the tail overlaps the figures (W > 1); what a machine loaded by others cannot show
    in wall time. What the drawing processes spent during the start-up (``early``), and
    between the last replication stored and the report's start (``beside``: the figures
    asked for ahead of it, while this process builds the index and the summaries, its CPU
    over that span ``alone``), on the cores it leaves idle, costs no wall time."""
    cores = max(1, workers)
    early = min(phases.get("early", 0.0), (cores - 1) * phases["before"])
    beside = min(phases.get("beside", 0.0), (cores - 1) * phases.get("alone", 0.0))
    return (phases["before"] + (phases["workers"] + phases["during"]) / cores
            + phases["after"] + (phases["drawing"] - early - beside) / cores)


def evaluate(users: int, days: int, seed: int, workers: int, profile: str | None = None
             ) -> tuple[Measured, dict[str, Any]]:
    """One ``opspec evaluate`` and the memory of its own process."""
    with tempfile.TemporaryDirectory() as tmp:
        args = ["evaluate", str(SPEC), "--users", str(users), "--days", str(days), "--seed",
                str(seed), "--workers", str(workers), "--user-model", str(USERS_TOML),
                "--quiet", "--json", "--out", str(Path(tmp) / "run")]
        if profile:
            prof = ("import cProfile, sys, time\nfrom opspec.cli import main\n"
                    "p = cProfile.Profile(time.process_time)\n"
                    "status = p.runcall(main, sys.argv[2:])\n"
                    "p.dump_stats(sys.argv[1])\nsys.exit(status)\n")
            run = Measured([sys.executable, "-c", prof, profile, *args], cwd=ROOT)
        else:
            run = Measured([sys.executable, "-c", _EVALUATE, *args], cwd=ROOT)
        doc = json.loads(run.stdout)
        assert doc["metrics"]["doses_due"]["users"] == users, doc["replications"]
        assert (Path(tmp) / "run" / "report.html").is_file()
    memory: dict[str, Any] = {}
    for line in run.stderr.splitlines():
        if line.startswith("@@memory "):
            memory = json.loads(line.split(" ", 1)[1])
    return run, memory


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.1f} (5 min {five:.1f}) on {os.cpu_count()} cores"


def _spread(values: list[float]) -> str:
    if len(values) == 1:
        return f"{values[0]:.2f}"
    return f"{statistics.median(values):.2f} (range {min(values):.2f}-{max(values):.2f})"


def speed(args: argparse.Namespace, script: Path) -> None:
    workers = [int(w) for w in args.workers.split(",")]
    names = ["baseline", "engine alone", *(f"evaluate --workers {w}" for w in workers)]
    cpu: dict[str, list[float]] = {n: [] for n in names}
    wall: dict[str, list[float]] = {n: [] for n in names}
    estimate: dict[int, list[float]] = {w: [] for w in workers}
    parts: dict[int, list[dict[str, float]]] = {w: [] for w in workers}
    at_once: dict[int, list[float]] = {w: [] for w in workers if w > 1}
    print(f"medication dispenser, {args.users:,} users x {args.days} days, seed {args.seed}, "
          f"{args.rounds} interleaved round(s); {_load()}")
    print(f"{'round':<7}" + "".join(f"{n:>24}" for n in names) + "   (CPU s / wall s)")
    for round_ in range(1, args.rounds + 1):
        evaluated = [evaluate(args.users, args.days, args.seed, w) for w in workers]
        runs = [baseline(script, args.users, args.days, args.seed),
                engine_alone(args.users, args.days, args.seed),
                *(run for run, _ in evaluated)]
        for w in at_once:
            at_once[w].append(baselines_at_once(script, args.users, args.days, args.seed, w))
        for w, (_, memory) in zip(workers, evaluated, strict=True):
            if "cpu" in memory:
                parts[w].append(memory["cpu"])
                estimate[w].append(estimated_wall(memory["cpu"], w))
        for name, run in zip(names, runs, strict=True):
            cpu[name].append(run.cpu)
            wall[name].append(run.wall)
        print(f"{round_:<7}" + "".join(f"{f'{r.cpu:.2f} / {r.wall:.2f}':>24}" for r in runs))
    base = cpu["baseline"]
    print(f"ratios, median of the rounds' own (each against its round's baseline); {_load()}")
    for name in names[1:]:
        ratios = [c / b for c, b in zip(cpu[name], base, strict=True)]
        goal = "   goal <= 1.5" if name == "evaluate --workers 1" else ""
        print(f"  {name + ' / baseline (CPU)':<44}{_spread(ratios)}{goal}")
    if "evaluate --workers 1" in cpu:
        over = [e / g for e, g in zip(cpu["evaluate --workers 1"], cpu["engine alone"],
                                      strict=True)]
        print(f"  {'evaluate --workers 1 / engine alone (CPU)':<44}{_spread(over)}")
        for w in workers:
            if w > 1:
                gain = [a / b for a, b in zip(wall["evaluate --workers 1"],
                                              wall[f"evaluate --workers {w}"], strict=True)]
                print(f"  {f'speed-up of --workers {w} over 1 (wall)':<44}{_spread(gain)}"
                      "   goal >= 1.8 on 2 idle cores")
                machine = [w * one / together for one, together
                           in zip(wall["baseline"], at_once[w], strict=True)]
                print(f"  {f'  the machine: {w} baselines at once over one':<44}"
                      f"{_spread(machine)}")
                label = f"  --workers {w} speed-up / the machine's"
                print(f"  {label:<44}"
                      f"{_spread([g / m for g, m in zip(gain, machine, strict=True)])}")
                if estimate[1] and estimate[w]:
                    est = [a / b for a, b in zip(estimate[1], estimate[w], strict=True)]
                    print(f"  {f'  estimated on {w} idle cores (CPU per part)':<44}"
                          f"{_spread(est)}")
    for w in workers:
        if parts[w]:
            mean = {k: statistics.median(p[k] for p in parts[w]) for k in parts[w][0]}
            print(f"  evaluate --workers {w}, CPU s by part (median): start-up "
                  f"{mean['before']:.2f}, storing {mean['during']:.2f} beside the workers' "
                  f"{mean['workers']:.2f}, tail {mean['after']:.2f}, figures' processes "
                  f"{mean['drawing']:.2f} ({mean.get('early', 0.0):.2f} of it during "
                  f"the start-up, {mean.get('beside', 0.0):.2f} beside the tail's first "
                  f"{mean.get('alone', 0.0):.2f})")


def memory(args: argparse.Namespace) -> None:
    sizes = [int(n) for n in args.memory.split(",")]
    workers = max(int(w) for w in args.workers.split(","))
    print(f"medication dispenser, 1 day, seed {args.seed}, --workers {workers}: memory of the "
          f"evaluate process itself; {_load()}")
    print(f"{'users':>9}{'peak MiB':>10}{'end MiB':>9}{'CPU s':>9}{'wall s':>9}")
    for users in sizes:
        run, mem = evaluate(users, 1, args.seed, workers)
        print(f"{users:>9,}{mem['peak_mib']:>10.1f}{mem['end_mib']:>9.1f}{run.cpu:>9.1f}"
              f"{run.wall:>9.1f}")


def instruction_counts(args: argparse.Namespace, script: Path) -> None:
    """Instructions of the baseline, the engine alone and ``evaluate --workers 1``, each
    under callgrind once, and their ratios (see the module docstring)."""
    from callgrind import instructions

    sizes = [str(args.users), str(args.days), str(args.seed)]
    run = "import sys\nfrom opspec.cli import main\nsys.exit(main(sys.argv[1:]))\n"
    os.environ["PYTHONHASHSEED"] = "0"
    print(f"medication dispenser, {args.users:,} users x {args.days} days, seed {args.seed}: "
          f"instructions (callgrind), each once; {_load()}")
    counts: dict[str, int] = {}
    counts["baseline"] = instructions(
        f"import runpy, sys\nsys.argv = [{str(script)!r}, '--users', {sizes[0]!r}, "
        f"'--days', {sizes[1]!r}, '--seed', {sizes[2]!r}]\n"
        f"runpy.run_path({str(script)!r}, run_name='__main__')\n", cwd=script.parent)
    counts["engine alone"] = instructions(_ENGINE, str(SPEC), str(USERS_TOML), *sizes[:2],
                                          sizes[2], cwd=ROOT)
    with tempfile.TemporaryDirectory() as tmp:
        counts["evaluate --workers 1"] = instructions(
            run, "evaluate", str(SPEC), "--users", sizes[0], "--days", sizes[1], "--seed",
            sizes[2], "--workers", "1", "--user-model", str(USERS_TOML), "--quiet", "--out",
            str(Path(tmp) / "run"), cwd=ROOT)
    for name, count in counts.items():
        print(f"  {name:<24}{count / 1e9:8.2f} G instructions   "
              f"{count / counts['baseline']:.2f} x the baseline")
    print(f"  evaluate --workers 1 / engine alone   "
          f"{counts['evaluate --workers 1'] / counts['engine alone']:.2f}")


def byte_compile() -> str:
    """Write the bytecode of opspec's Python modules, as ``pip install`` or a first run leaves
    it on a user's machine, and say so. Where ``PYTHONDONTWRITEBYTECODE`` is set (this
    project's sessions set it) no run writes it, and every ``opspec evaluate`` compiled the
    source of each module it imports again: about 0.45 G instructions (0.2-0.35 CPU-s) of its
    start-up, which the baseline (one small script, SimPy's bytecode installed) does not pay.
    ``--no-bytecode`` measures that way instead (nothing is written; modules compiled before
    are still read)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "opspec")],
                   check=True, env=env, cwd=ROOT)
    return "opspec's bytecode written before measuring (as an install leaves it)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--users", type=int, default=1000)
    parser.add_argument("--days", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    parser.add_argument("--workers", default="1",
                        help="comma-separated worker counts of evaluate (default 1)")
    parser.add_argument("--memory", metavar="USERS,...",
                        help="instead: memory of evaluate --days 1 at these numbers of users")
    parser.add_argument("--instructions", action="store_true",
                        help="instead: callgrind instruction counts of the baseline, the "
                        "engine alone and evaluate --workers 1, each once")
    parser.add_argument("--profile", metavar="FILE",
                        help="also write a CPU-time cProfile of one evaluate --workers 1")
    parser.add_argument("--no-bytecode", action="store_true",
                        help="do not write opspec's bytecode first (see byte_compile)")
    args = parser.parse_args()
    version = Measured([sys.executable, "-m", "opspec", "--version"], cwd=ROOT).stdout
    print(" ".join(version.split()))
    if not args.no_bytecode:
        print(byte_compile())
    if args.memory:
        memory(args)
    else:
        script = _baseline_script()
        if script is None:
            sys.exit("baseline not found: put shared/bench/handcoded_simpy.py beside a folder "
                     "above this checkout, or set OPSPEC_BENCH to its folder")
        if args.instructions:
            instruction_counts(args, script)
        else:
            speed(args, script)
    if args.profile:
        evaluate(args.users, args.days, args.seed, 1, profile=args.profile)
        print(f"profile of one evaluate --workers 1: {args.profile} (python -m pstats)")


if __name__ == "__main__":
    main()
