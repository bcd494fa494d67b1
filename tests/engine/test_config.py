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
    ("wokers = 2", r"engine.toml: wokers: unknown engine option 'wokers'"),
    ('processor_model = "fast"', (r"processor_model: processor_model 'fast' is not known "
                                 r"\(allowed values: dedicated, pooled, preemptive, "
                                 r"priority-queues\)")),
    ("workers = 0", r"workers: workers must be a whole number >= 1"),
    ("switch_cost = -1.0", r"switch_cost: switch_cost must be a number of seconds >= 0"),
    ("speed = 0", r"speed: speed must be a number > 0"),
    ("workers = [", r"engine.toml: not valid TOML"),
], ids=["unknown-key", "bad-model", "zero-workers", "negative-switch", "zero-speed", "syntax"])
def test_bad_configuration_names_file_key_and_allowed_values(tmp_path: Path, text: str,
                                                            message: str) -> None:
    path = tmp_path / "engine.toml"
    path.write_text(text + "\n")
    with pytest.raises(ConfigurationError, match=message):
        EngineConfig.load(path)


def test_keyword_overrides_are_validated_too() -> None:
    with pytest.raises(ConfigurationError, match="<options>: workers"):
        EngineConfig().with_options(workers=-1)
    with pytest.raises(ConfigurationError, match="timer_resolution"):
        EngineConfig(timer_resolution=-0.5)
