"""Engine configuration from TOML and keyword overrides."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.config import EngineConfig
from opspec.errors import ConfigurationError


def test_config_loads_from_an_engine_table_and_applies_overrides(tmp_path: Path) -> None:
    path = tmp_path / "engine.toml"
    path.write_text('[engine]\nprocessor_model = "pooled"\nworkers = 3\nswitch_cost = 0.002\n')
    config = EngineConfig.load(path, priorities=4)
    assert (config.processor_model, config.workers, config.switch_cost, config.priorities) == (
        "pooled", 3, 0.002, 4)


@pytest.mark.parametrize(("text", "message"), [
    ("wokers = 2", r"engine.toml:1: wokers: unknown engine option 'wokers'"),
    ('processor_model = "fast"', (r"engine.toml:1: processor_model: processor_model 'fast' is not known "
                                 r"\(allowed values: dedicated, pooled, preemptive, "
                                 r"priority-queues\)")),
    ("workers = 0", r"engine.toml:1: workers: workers must be a whole number >= 1"),
    ("switch_cost = -1.0", (r"engine.toml:1: switch_cost: switch_cost must be a number of "
                            r"seconds >= 0")),
    ("speed = 0", r"engine.toml:1: speed: speed must be a number > 0"),
    ("workers = [", r"engine.toml: not valid TOML"),
    ("workers = = 2", r"engine.toml:1: not valid TOML"),
], ids=["unknown-key", "bad-model", "zero-workers", "negative-switch", "zero-speed", "syntax",
        "syntax-at-a-line"])
def test_bad_configuration_names_file_line_key_and_allowed_values(tmp_path: Path, text: str,
                                                            message: str) -> None:
    path = tmp_path / "engine.toml"
    path.write_text(text + "\n")
    with pytest.raises(ConfigurationError, match=message):
        EngineConfig.load(path)


def test_a_bad_key_in_the_engine_table_is_placed_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "engine.toml"
    path.write_text('# tuned for the board\n[engine]\nprocessor_model = "pooled"\nwokers = 2\n')
    with pytest.raises(ConfigurationError) as refused:
        EngineConfig.load(path)
    assert str(refused.value).startswith(f"{path}:4: wokers: unknown engine option 'wokers'")


def test_a_key_outside_the_engine_table_is_refused_not_ignored(tmp_path: Path) -> None:
    # workers = 4 above [engine] was left out without a word: the run used 1 worker
    path = tmp_path / "engine.toml"
    path.write_text('workers = 4\n[engine]\nprocessor_model = "pooled"\n')
    with pytest.raises(ConfigurationError) as refused:
        EngineConfig.load(path)
    assert str(refused.value).startswith(
        f"{path}:1: workers: 'workers' is outside the [engine] table, so it would be ignored; "
        "move it under [engine]")


def test_keyword_overrides_are_validated_too() -> None:
    with pytest.raises(ConfigurationError, match="--workers must be a whole number >= 1"):
        EngineConfig().with_options(workers=-1)
    with pytest.raises(ConfigurationError, match="timer_resolution"):
        EngineConfig(timer_resolution=-0.5)


def test_a_bad_command_line_option_is_named_as_the_option_not_a_file_key(
        capsys: pytest.CaptureFixture[str]) -> None:
    # `opspec run ... --speed 0 --realtime` said "<options>: speed: ... write e.g. speed = 60":
    # an internal label, and TOML for an option given on the command line.
    from opspec.cli import main

    spec = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
    status = main(["run", str(spec), "--speed", "0", "--realtime"])
    err = capsys.readouterr().err
    assert status == 2
    assert "--speed must be a number > 0, not 0;" in err
    assert "e.g. --speed 60" in err
    assert "<options>" not in err and "speed =" not in err
    with pytest.raises(ConfigurationError) as caught:
        EngineConfig().with_options(processor_model="pooled", switch_cost=-1.0)
    assert str(caught.value) == ("--switch-cost must be a number of seconds >= 0, not -1 "
                                 "(e.g. --switch-cost 0.001)")


def test_a_bad_value_in_the_engine_file_keeps_the_file_and_key(tmp_path: Path) -> None:
    path = tmp_path / "engine.toml"
    path.write_text("speed = 0\n")
    with pytest.raises(ConfigurationError) as caught:
        EngineConfig.load(path, realtime=True)
    assert str(caught.value) == (f"{path}:1: speed: speed must be a number > 0, not 0; write "
                                 "e.g. speed = 60 (one simulated minute per wall second)")
