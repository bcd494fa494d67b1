"""The two processor models under load: the dedicated model gives every workflow instance its
own worker; the pooled model shares N workers through per-priority FIFO queues and pays a
context switch per general activity. A constructed overload shows what the design predicts."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.engine.timing import TimingListener
from opspec.xpdl.loader import load_spec

WORKFLOW = """
    <WorkflowProcess Id="{id}" Name="{id}">
      <ProcessHeader/>
      <Activities>
        <Activity Id="start"><Event><StartEvent/></Event></Activity>
        <Activity Id="work"><Implementation><No/></Implementation>
          <ExtendedAttributes><ExtendedAttribute Name="opspec:CpuDemand" Value="{cpu}"/>
          </ExtendedAttributes></Activity>
        <Activity Id="end"><Event><EndEvent/></Event></Activity>
      </Activities>
      <Transitions>
        <Transition Id="t1" From="start" To="work"/><Transition Id="t2" From="work" To="end"/>
      </Transitions>
      <ExtendedAttributes>
        <ExtendedAttribute Name="opspec:Period" Value="{period}"/>
        <ExtendedAttribute Name="opspec:Priority" Value="{priority}"/>
        {deadline}
      </ExtendedAttributes>
    </WorkflowProcess>"""


def spec(tmp_path: Path, *workflows: dict[str, object]) -> Path:
    body = "".join(WORKFLOW.format(
        id=w["id"], cpu=w["cpu"], period=w["period"], priority=w["priority"],
        deadline=(f'<ExtendedAttribute Name="opspec:Deadline" Value="{w["deadline"]}"/>'
                  if "deadline" in w else "")) for w in workflows)
    path = tmp_path / "load.xpdl"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="load" Name="load">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created>
  </PackageHeader>
  <WorkflowProcesses>{body}
  </WorkflowProcesses>
</Package>""", encoding="utf-8")
    return path


def timing(path: Path, until: float = 10.0, **config: object) -> tuple[dict, dict]:
    listener = TimingListener()
    sim = Simulation(load_spec(path), EngineConfig(**config), listeners=[listener])
    result = sim.run(until=until)
    return listener.summary(), result.summary


CONTROL = {"id": "control", "cpu": "20ms", "period": "50ms", "priority": 1,
           "deadline": "30ms"}
LOGGER = {"id": "logger", "cpu": "30ms", "period": "100ms", "priority": 5}


def test_overload_pooled_single_worker_misses_deadlines_the_dedicated_model_meets(tmp_path):
    path = spec(tmp_path, CONTROL, LOGGER)
    dedicated, _ = timing(path)
    pooled, summary = timing(path, processor_model="pooled", workers=1)
    assert dedicated["control"]["misses"] == 0
    assert dedicated["control"]["response_max_s"] == pytest.approx(0.020)
    # one worker must serve 20 ms every 50 ms plus 30 ms every 100 ms: 70 % busy, and the
    # higher-priority logger delays control past its 30 ms deadline
    assert pooled["control"]["misses"] > 0
    assert pooled["control"]["response_max_s"] > 0.030
    assert summary["pool"]["switches"] > 0


def test_a_second_worker_removes_the_misses(tmp_path):
    path = spec(tmp_path, CONTROL, LOGGER)
    pooled, _ = timing(path, processor_model="pooled", workers=2)
    assert pooled["control"]["misses"] == 0


def test_priority_order_decides_who_waits_in_the_queue(tmp_path):
    # the blocker takes the single worker at each release, so control and logger both queue;
    # the pooled model then serves the higher priority first (non-preemptive)
    blocker = {"id": "blocker", "cpu": "10ms", "period": "100ms", "priority": 0}
    control = {"id": "control", "cpu": "20ms", "period": "100ms", "deadline": "35ms"}
    high, _ = timing(spec(tmp_path, blocker, {**control, "priority": 6}, LOGGER),
                     processor_model="pooled", workers=1)
    low, _ = timing(spec(tmp_path, blocker, {**control, "priority": 1}, LOGGER),
                    processor_model="pooled", workers=1)
    assert high["control"]["response_max_s"] == pytest.approx(0.030)   # 10 blocker + 20 own
    assert high["control"]["misses"] == 0
    assert low["control"]["response_max_s"] == pytest.approx(0.060)    # + 30 of the logger
    assert low["control"]["misses"] == low["control"]["started"]
    assert high["logger"]["response_mean_s"] > low["logger"]["response_mean_s"]


def test_switch_cost_is_paid_per_general_activity(tmp_path):
    path = spec(tmp_path, {"id": "solo", "cpu": "5ms", "period": "100ms", "priority": 1})
    pooled, summary = timing(path, until=1.0, processor_model="pooled", workers=1,
                             switch_cost=0.002)
    assert pooled["solo"]["response_mean_s"] == pytest.approx(0.007)
    assert summary["pool"]["busy_time"] == pytest.approx(pooled["solo"]["completed"] * 0.007,
                                                         rel=0.2)


def test_jitter_on_a_known_schedule(tmp_path):
    path = spec(tmp_path, CONTROL, LOGGER)
    dedicated, _ = timing(path)
    assert dedicated["control"]["jitter_s"] == pytest.approx(0.0, abs=1e-9)
    pooled, _ = timing(path, processor_model="pooled", workers=1)
    t = pooled["control"]
    assert t["jitter_s"] == pytest.approx(t["response_max_s"] - min_response(path))


def min_response(path: Path) -> float:
    listener = TimingListener()
    Simulation(load_spec(path), EngineConfig(processor_model="pooled", workers=1),
               listeners=[listener]).run(until=10.0)
    return min(listener.workflows["control"].responses)


def test_dedicated_model_counts_its_cpu_bursts_and_the_most_under_way_at_once(tmp_path):
    path = spec(tmp_path, CONTROL, LOGGER)
    dedicated, summary = timing(path, until=1.0)
    # control bursts at 0, 50, ... 950 ms (20), logger at 0, 100, ... 900 ms (10); both at 0
    assert summary["dedicated"] == {"bursts": 30, "busy_time": pytest.approx(0.7),
                                    "max_busy": 2}
    # a pooled run with that many workers and no switch cost waits for nothing
    pooled, _ = timing(path, until=1.0, processor_model="pooled",
                       workers=summary["dedicated"]["max_busy"])
    assert pooled == dedicated


def cli(capsys, *args: str) -> tuple[int, str, str]:
    from opspec.cli import main

    status = main(["run", *args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize("option", [["--workers", "3"], ["--switch-cost", "0.01"]],
                         ids=["workers", "switch-cost"])
def test_pooled_only_options_with_the_dedicated_model_are_refused(option, capsys):
    status, _, err = cli(capsys, "specs/vacuum_cleaner.xpdl", "--until", "1", *option)
    assert status == 2
    assert "applies to the shared-processor models only" in err
    assert "unlimited processors" in err


def test_timing_says_the_dedicated_model_has_a_worker_per_instance(capsys):
    status, out, _ = cli(capsys, "specs/vacuum_cleaner.xpdl", "--until", "5", "--timing",
                         "--timeline", "none")
    assert status == 0
    assert "one worker per workflow instance (unlimited processors" in out
    assert "at most 3 at once" in out


def test_readme_command_shows_pooled_misses_the_dedicated_model_meets(capsys):
    """README: --processor-model pooled --workers 1 --switch-cost 0.01 on the vacuum."""
    import json

    common = ["specs/vacuum_cleaner.xpdl", "--until", "60", "--timing", "--json"]
    status, out, _ = cli(capsys, *common)
    dedicated = json.loads(out)["timing"]
    status_pooled, out, _ = cli(capsys, *common, "--processor-model", "pooled", "--workers", "1",
                                "--switch-cost", "0.01")
    pooled = json.loads(out)["timing"]
    assert status == status_pooled == 0
    assert sum(t["misses"] for t in dedicated.values()) == 0
    assert pooled["sense"]["misses"] > 0


def test_processor_models_benchmark_runs_at_tiny_size(capsys, load_benchmark):
    module = load_benchmark("processor_models")
    module.main(["--seconds", "2"])
    out = capsys.readouterr().out
    assert "dedicated (3 cpu)" in out
    assert "pooled 1w 1p" in out and "pooled 3w 8p" in out


def test_table3_benchmark_runs_at_tiny_size_with_the_same_work_in_both_variants(capsys, load_benchmark):
    module = load_benchmark("table3_overhead")
    module.main(["--seconds", "30", "--repeat", "1"])
    rows = [line.split() for line in capsys.readouterr().out.splitlines()
            if "workflows & engine" in line or "customised code" in line]
    # each row: [application words...] variant words, activations, CPU s, RSS MiB[, overhead]
    activations = [int(next(w for w in row if w.isdigit())) for row in rows]
    assert activations == [300, 300, 300, 300]
