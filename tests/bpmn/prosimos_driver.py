"""Run one model through Prosimos (in .prosimos-venv, never opspec's own environment) and
print, as JSON, each case's cycle time (seconds, its first activity enabled to its last
activity ended) and the activities it ran.

Usage: python prosimos_driver.py MODEL.bpmn PARAMETERS.json CASES SEED OUT_DIR
"""

from __future__ import annotations

import csv
import json
import random
import sys
from datetime import datetime
from pathlib import Path


def main() -> None:
    bpmn, parameters, cases, seed, out = sys.argv[1:6]
    import numpy as np
    from prosimos.simulation_engine import run_simulation

    # Prosimos draws from the global generators of random, numpy and scipy.stats
    random.seed(int(seed))
    np.random.seed(int(seed))
    log = Path(out) / "prosimos_log.csv"
    run_simulation(bpmn, parameters, int(cases), log_out_path=str(log),
                   starting_at="2026-01-05T00:00:00.000000+00:00")
    cases_seen: dict[str, dict[str, object]] = {}
    with log.open(newline="", encoding="utf-8") as handle:
        for row in csv.DictReader(handle):
            case = cases_seen.setdefault(row["case_id"], {"first": None, "last": None,
                                                          "activities": []})
            enabled = datetime.fromisoformat(row["enable_time"])
            ended = datetime.fromisoformat(row["end_time"])
            if case["first"] is None or enabled < case["first"]:  # type: ignore[operator]
                case["first"] = enabled
            if case["last"] is None or ended > case["last"]:  # type: ignore[operator]
                case["last"] = ended
            case["activities"].append(row["activity"])  # type: ignore[union-attr]
    result = [{"cycle": (c["last"] - c["first"]).total_seconds(),  # type: ignore[operator]
               "activities": c["activities"]} for c in cases_seen.values()]
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main()
