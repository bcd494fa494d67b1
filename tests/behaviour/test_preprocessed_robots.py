"""A robot spec preprocessed to standard XPDL (``opspec preprocess``) runs like the SISARL file:
the generated tasks calling ``opspec.supervisor.push``/``pull`` and ``opspec.engine.mode_change``
are run as the built-ins they stand for, so a fixed seed gives the same outcomes."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.engine.simulation import RunResult, Simulation
from opspec.errors import SpecError
from opspec.worlds import world_performers
from opspec.xpdl.open_spec import open_spec
from opspec.xpdl.preprocess import preprocess_to_xpdl

SPECS = Path(__file__).resolve().parents[2] / "specs"


def copy_spec(tmp_path: Path, name: str, fast_drain: bool = False) -> Path:
    spec = tmp_path / f"{name}.xpdl"
    text = (SPECS / f"{name}.xpdl").read_text(encoding="utf-8")
    if fast_drain:                       # the battery runs low at 80 s: a mode change to dock
        text = text.replace('<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>',
                            '<ExtendedAttribute Name="opspec:World" Value="vacuum-room">'
                            '<opspec:Parameter Name="drain_per_s" Value="1.0"/>'
                            '</ExtendedAttribute>')
    spec.write_text(text, encoding="utf-8")
    world = SPECS / f"{name}.world.toml"
    if world.is_file():
        shutil.copy(world, tmp_path / world.name)
    return spec


def preprocessed(spec: Path) -> Path:
    data, _ = preprocess_to_xpdl(open_spec(spec))
    out = spec.with_name(spec.stem + ".std.xpdl")
    out.write_bytes(data)
    return out


def run(path: Path, until: float, seed: int) -> RunResult:
    compiled = compile_package(open_spec(path))
    return Simulation(compiled, performers=world_performers(compiled, seed=seed, user=0),
                      seed=seed, keep_trace=True).run(until=until)


def outcome(result: RunResult) -> dict[str, object]:
    metrics = {name: m.get("total", m.get("value", m.get("n")))
               for name, m in result.metrics.items()}
    return {"metrics": metrics, "mode": result.summary["mode"],
            "instances": result.summary["instances"]}


@pytest.mark.parametrize("name, seed, until, fast_drain", [
    ("vacuum_cleaner", 1, 120.0, False),
    ("toy_sumo", 2, 150.0, False),
    ("medication_cart_guidance", 0, 120.0, False),
    ("vacuum_cleaner", 0, 100.0, True),
], ids=["vacuum", "sumo", "cart", "vacuum-docks"])
def test_preprocessed_robot_runs_like_the_sisarl_spec(tmp_path, name, seed, until, fast_drain):
    spec = copy_spec(tmp_path, name, fast_drain)
    native = run(spec, until, seed)
    standard = run(preprocessed(spec), until, seed)
    assert outcome(standard) == outcome(native)
    # what the built-ins do shows in the preprocessed run: pulled data and the mode change
    pulled = [e for e in standard.trace if e.kind == "data.changed"
              and e.process == "avoid" and "seen" in (e.data or {})]
    assert pulled
    if fast_drain:
        changes = [(e.time, e.data["to"]) for e in standard.trace if e.kind == "mode.changed"]
        assert changes == [(pytest.approx(80.001), "dock")]


def test_a_preprocessed_call_with_parameters_that_do_not_fit_is_a_spec_error(tmp_path):
    spec = preprocessed(copy_spec(tmp_path, "vacuum_cleaner"))
    text = spec.read_text(encoding="utf-8")
    spec.write_text(text.replace('<ActualParameter>"range"</ActualParameter>',
                                 "<ActualParameter>range_channel</ActualParameter>", 1),
                    encoding="utf-8")
    with pytest.raises(SpecError, match="opspec.supervisor.push.*channel as a string literal"):
        compile_package(open_spec(spec))


def test_validate_finds_a_preprocessed_mode_change_to_an_undeclared_mode(tmp_path, capsys):
    from opspec.cli import main

    spec = preprocessed(copy_spec(tmp_path, "vacuum_cleaner"))
    text = spec.read_text(encoding="utf-8")
    assert '<ActualParameter>"dock"</ActualParameter>' in text
    spec.write_text(text.replace('<ActualParameter>"dock"</ActualParameter>',
                                 '<ActualParameter>"sleep"</ActualParameter>'), encoding="utf-8")
    assert main(["validate", str(spec)]) == 1
    out = capsys.readouterr().out
    assert "changes to mode 'sleep', which the package does not declare" in out
    assert main(["run", str(spec), "--until", "1"]) == 1
