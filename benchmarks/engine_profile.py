"""Profile the engine on the dispenser scenario against the hand-coded SimPy baseline.

    .venv/bin/python benchmarks/engine_profile.py --users 1000 --days 30 --seed 1
        [--mode separate|shared] [--baseline] [--profile]

The engine runs the Python-built dispenser model (tests/engine/dispenser_model.py) with a
trivial stochastic user that draws exactly the baseline's samples (common random numbers:
user u's stream is SeedSequence(seed, spawn_key=(u,)), one draw_day per day), so taken /
missed / alarm counts must agree with the baseline *exactly*.

--mode separate: one Simulation (own SimPy environment) per household, run one after another.
--mode shared:   all households as Simulations on one shared environment.
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import json
import pstats
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT.parent / "shared" / "bench"
sys.path.insert(0, str(ROOT / "tests" / "engine"))
sys.path.insert(0, str(BENCH))

import numpy as np
from scenario import DEADLINE, DOSE_TIMES, WRONG_EXTRA, draw_day

from opspec.engine.compiled import compile_package
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation

DAY = 86_400.0


class BenchUser:
    """The scenario's user lane decisions, fed by the baseline's per-user samples."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.days: list[list[tuple[Any, ...]]] = []
        self.walking_dose = -1
        self.session: PerformerSession | None = None
        self.wrong_pressed = -1

    def attach(self, session: PerformerSession) -> None:
        self.session = session

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass

    def _sample(self, t: float) -> tuple[int, int, tuple[Any, ...]]:
        day = int(t // DAY)
        while len(self.days) <= day:
            self.days.append(draw_day(self.rng))
        tod = t - day * DAY
        slot = 0
        for i, dose in enumerate(DOSE_TIMES):
            if tod + 1e-6 >= dose:
                slot = i
        k = round((tod - DOSE_TIMES[slot]) / DEADLINE)
        return day * 4 + slot, k, self.days[day][slot]

    def offer(self, item: WorkItem) -> None:
        session = self.session
        assert session is not None
        activity = item.activity
        if activity == "hear_alarm":
            dose, k, sample = self._sample(item.offered_at)
            if self.walking_dose == dose or not sample[k]:
                session.omit(item)
                return
            self.walking_dose = dose
            session.complete(item)
        elif activity == "walk_to_dispenser":
            _dose, _k, sample = self._sample(item.offered_at)
            session.call_later(sample[3], lambda: session.complete(item))
        elif activity == "choose_button":
            dose, _k, sample = self._sample(self.walk_start(item))
            if sample[4] and self.wrong_pressed != dose:
                self.wrong_pressed = dose
                session.complete(item, choice="press_wrong_button")
            elif self.wrong_pressed == dose and sample[4] and item.offered_at >= 0:
                self.wrong_pressed = -2 - dose           # pressed wrong; report after 10 s
                session.call_later(WRONG_EXTRA,
                                   lambda: session.complete(item, choice="press_report"))
            else:
                session.complete(item, choice="press_report")
        elif activity == "take_pill":
            _dose, _k, sample = self._sample(self.walk_start(item))
            session.call_later(sample[5], lambda: session.complete(item))
        else:
            session.complete(item)

    def walk_start(self, item: WorkItem) -> float:
        # the dose this user walks for (offers after walking may be past the 900 s window)
        day, slot = divmod(self.walking_dose, 4)
        return day * DAY + DOSE_TIMES[slot]


def run_engine(users: int, days: int, seed: int, mode: str) -> dict[str, Any]:
    from dispenser_model import dispenser_package

    t0 = time.perf_counter()
    compiled = compile_package(dispenser_package())
    until = days * DAY
    taken = missed = alarms = due = 0
    latencies: list[float] = []
    sims = []
    if mode == "shared":
        import simpy
        env = simpy.Environment()
        for u in range(users):
            sims.append(Simulation(compiled, performers={"user": BenchUser(user_stream(seed, u))},
                                   seed=seed, scope=(u,), env=env))
        for sim in sims:
            sim.boot()
        env.run(until=until)
        results = [sim.result() for sim in sims]
    else:
        results = []
        for u in range(users):
            sim = Simulation(compiled, performers={"user": BenchUser(user_stream(seed, u))},
                             seed=seed, scope=(u,))
            results.append(sim.run(until=until))
            latencies.extend(sim.metrics.samples["report_latency_s"])
    for sim, res in zip(sims, results, strict=False):
        latencies.extend(sim.metrics.samples["report_latency_s"])
    for res in results:
        m = res.metrics
        taken += m["doses_taken"]["total"]
        missed += m["doses_missed"]["total"]
        alarms += m["alarms"]["total"]
        due += m["doses_due"]["total"]
    wall = time.perf_counter() - t0
    lat = np.asarray(latencies)
    done = taken + missed
    return {"impl": f"opspec_engine_{mode}", "users": users, "days": days, "seed": seed,
            "cycles": users * days * 4, "wall_s": round(wall, 4),
            "cycles_per_s": round(users * days * 4 / wall, 1), "doses": due, "taken": taken,
            "missed": missed, "miss_pct": round(100.0 * missed / done, 4) if done else None,
            "lat_mean_s": round(float(lat.mean()), 4) if lat.size else None,
            "lat_p95_s": round(float(np.percentile(lat, 95)), 4) if lat.size else None,
            "alarms_per_dose": round(alarms / done, 5) if done else None}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--users", type=int, default=1000)
    ap.add_argument("--days", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mode", choices=("separate", "shared"), default="separate")
    ap.add_argument("--baseline", action="store_true", help="also run the hand-coded baseline")
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="repeats for --baseline (min taken)")
    a = ap.parse_args()
    if a.profile:
        profiler = cProfile.Profile()
        profiler.enable()
        rec = run_engine(a.users, a.days, a.seed, a.mode)
        profiler.disable()
        pstats.Stats(profiler).sort_stats("tottime").print_stats(25)
    else:
        rec = run_engine(a.users, a.days, a.seed, a.mode)
    print(json.dumps(rec))
    if a.baseline:
        import handcoded_simpy

        base_runs, engine_runs = [], []
        for _ in range(a.repeat):            # interleaved: both see the same machine load
            base_runs.append(handcoded_simpy.run(a.users, a.days, a.seed))
            t0 = time.process_time()
            run_engine(a.users, a.days, a.seed, a.mode)
            engine_runs.append(time.process_time() - t0)
        base = min(base_runs, key=lambda r: r["cpu_s"])
        print(json.dumps({k: base[k] for k in ("impl", "cpu_s", "taken", "missed",
                                               "lat_mean_s", "alarms_per_dose")}))
        print(json.dumps({"engine_cpu_s": round(min(engine_runs), 3),
                          "baseline_cpu_s": base["cpu_s"],
                          "ratio_cpu": round(min(engine_runs) / base["cpu_s"], 3),
                          "same_outcomes": all(rec[k] == base[k] for k in
                                               ("taken", "missed", "alarms_per_dose"))}))


if __name__ == "__main__":
    gc.collect()
    main()
