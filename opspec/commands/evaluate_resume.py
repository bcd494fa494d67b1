"""A stored evaluation (``OUT/results.sqlite``): the parameters written into its ``run``
table when it starts, and whether it may be resumed (``--resume``) with the options and
files given now."""
from __future__ import annotations

import argparse
import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from opspec.commands.evaluate_exports import export_formats
from opspec.commands.evaluate_plan import engine_settings
from opspec.errors import EvaluationError

__all__ = ["check_unchanged", "resume_differences", "same_file", "store_parameters",
           "user_model_digest"]


def user_model_digest(plan: Any) -> str | None:
    """SHA-256 of the user-model file (None for presets: they change with opspec itself)."""
    from opspec.evaluation.plan import file_digest

    if plan.user_model is None or not Path(plan.user_model).is_file():
        return None
    return file_digest(plan.user_model)


def store_parameters(store: Any, plan: Any, definitions: dict[str, list[dict[str, Any]]],
                      version: str) -> None:
    """The ``run`` table: the plan (what ``--resume`` re-runs) and, as separate keys for
    readers of the database, the parameters it is made of."""
    a = plan.design("A")
    store.put("plan", plan.to_json())
    store.put("metrics", definitions["A"])
    for label, declared in definitions.items():
        if label != "A":
            store.put(f"metrics_{label}", declared)
    store.put("spec", a.spec)
    store.put("spec_sha256", a.sha256)
    store.put("designs", [{"label": d.label, "spec": d.spec, "sha256": d.sha256}
                          for d in plan.designs])
    store.put("users", plan.users)
    store.put("days", plan.days)
    store.put("seed", plan.seed)
    store.put("user_model", plan.user_model)
    store.put("user_model_sha256", user_model_digest(plan))
    store.put("opspec_version", version)
    # NumPy does not promise the same random numbers from one version to the next (NEP 19):
    # the versions a run's numbers came from, for whoever reproduces them
    import platform

    import numpy

    store.put("python_version", platform.python_version())
    store.put("numpy_version", numpy.__version__)
    store.put("started", datetime.now(UTC).isoformat(timespec="seconds"))


def same_file(given: str | None, stored: str | None) -> bool:
    """Whether two spellings name the same file (or preset): ``specs/a.xpdl`` and
    ``./specs/a.xpdl`` do."""
    if given is None or stored is None:
        return given == stored
    if given == stored:
        return True
    try:
        return Path(given).resolve() == Path(stored).resolve() and Path(given).exists()
    except OSError:
        return False


def resume_differences(args: argparse.Namespace, plan: Any) -> list[str]:
    """Each option given with ``--resume`` that differs from the stored run, as
    ``--users 8 (stored: 4)``: resuming with them would silently mix two runs, or ignore
    what the user asked for. Options not given take the stored values."""
    differs: list[str] = []
    a = plan.design("A")
    if args.spec is not None and not same_file(args.spec, a.spec):
        differs.append(f"SPEC {args.spec} (stored: {a.spec})")
    if args.users is not None and args.users != plan.users:
        differs.append(f"--users {args.users} (stored: {plan.users})")
    if args.days is not None and float(args.days) != float(plan.days):
        differs.append(f"--days {args.days:g} (stored: {plan.days:g})")
    if args.seed is not None and args.seed != plan.seed:
        differs.append(f"--seed {args.seed} (stored: {plan.seed})")
    if args.user_model is not None and not same_file(args.user_model, plan.user_model):
        differs.append(f"--user-model {args.user_model} (stored: "
                       f"{plan.user_model or 'none'})")
    if args.compare is not None:
        b = next((d for d in plan.designs if d.label == "B"), None)
        if b is None or not same_file(args.compare, b.spec):
            differs.append(f"--compare {args.compare} (stored: "
                           f"{b.spec if b is not None else 'no second design'})")
    if args.engine_config is not None:
        engine = engine_settings(args.engine_config)
        if json.dumps(engine, sort_keys=True) != json.dumps(dict(plan.engine), sort_keys=True):
            changed = sorted(k for k in set(engine) | set(plan.engine)
                             if engine.get(k) != plan.engine.get(k))
            differs.append(f"--engine-config {args.engine_config} ("
                           + ", ".join(f"{k} {engine.get(k)!r}, stored "
                                       f"{plan.engine.get(k)!r}" for k in changed[:4]) + ")")
    if args.export:
        export = export_formats(args.export)
        if export != tuple(plan.export):
            differs.append(f"--export {','.join(export)} (stored: "
                           f"{','.join(plan.export) or 'none'})")
    if args.case is not None and args.case != plan.case:
        differs.append(f"--case {args.case} (stored: {plan.case})")
    if args.input_uncertainty is not None and args.input_uncertainty != plan.input_uncertainty:
        differs.append(f"--input-uncertainty {args.input_uncertainty} (stored: "
                       f"{plan.input_uncertainty or 'none'})")
    if args.users_per_draw is not None and args.users_per_draw != plan.users_per_draw:
        differs.append(f"--users-per-draw {args.users_per_draw} (stored: "
                       f"{plan.users_per_draw or 'none'})")
    return differs


def check_unchanged(store: Any, plan: Any) -> None:
    """Refuse to resume when a spec or the user-model file changed since the run started:
    the finished and the remaining users would then describe different designs."""
    from opspec.evaluation.plan import file_digest

    changed = [f"{d.spec} changed since the run started (its content's SHA-256 is now "
               f"{file_digest(d.spec)[:12]}…, the stored run's {d.sha256[:12]}…)"
               for d in plan.designs if file_digest(d.spec) != d.sha256]
    stored_model = store.get("user_model_sha256")
    if stored_model is not None:
        now = user_model_digest(plan)
        if now != stored_model:
            changed.append(f"{plan.user_model} changed since the run started (its content's "
                           f"SHA-256 is now {now[:12] + '…' if now else 'unreadable'}, the "
                           f"stored run's {stored_model[:12]}…)")
    if changed:
        store.close()
        raise EvaluationError(
            f"{store.folder}: cannot resume, {'; '.join(changed)}",
            hint="restore the files as they were, or start a new run with another --out")
