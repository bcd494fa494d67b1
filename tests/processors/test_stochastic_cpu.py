"""Stochastic execution times: ``opspec:CpuDemand`` given as a distribution is drawn at every
execution (from the activity's own seeded stream), and ``--timing`` reports response-time
percentiles with intervals.

Reference: one workflow started every T = 1 s on one processor, its one activity needing an
exponential processor time of mean 1/mu = 0.7 s: the D/M/1 queue (GI/M/1 with deterministic
arrivals; L. Kleinrock, *Queueing Systems* Vol. 1, 1975, §6.4). Its response (sojourn) time is
exponential with rate mu(1 - sigma), sigma the root in (0, 1) of sigma = exp(-mu T (1 - sigma)):
mean 1/(mu(1 - sigma)), the q-quantile -ln(1 - q)/(mu(1 - sigma)). Consecutive responses of a
queue are correlated, so the sampling error is taken from 20 batch means (each of 2,000
instances), with a 99 % t interval.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from scipy.optimize import brentq
from scipy.stats import t as student_t

from opspec.cli import main
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.engine.timing import TimingListener
from opspec.xpdl.loader import load_spec

NS = "http://www.wfmc.org/2008/XPDL2.1"
MEAN_S, PERIOD_S = 0.7, 1.0


def spec(tmp_path: Path, demand: str) -> Path:
    path = tmp_path / "dm1.xpdl"
    path.write_text(
        f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="dm1">'
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created>"
        '</PackageHeader><WorkflowProcesses><WorkflowProcess Id="job"><ProcessHeader/>'
        '<Activities><Activity Id="work"><Implementation><No/></Implementation>'
        '<ExtendedAttributes><ExtendedAttribute Name="opspec:CpuDemand" '
        f'Value="{demand}"/></ExtendedAttributes></Activity></Activities><ExtendedAttributes>'
        f'<ExtendedAttribute Name="opspec:Period" Value="{PERIOD_S}"/>'
        "</ExtendedAttributes></WorkflowProcess></WorkflowProcesses></Package>",
        encoding="utf-8")
    return path


def responses(path: Path, until: float, seed: int = 0) -> list[float]:
    listener = TimingListener()
    Simulation(load_spec(path), EngineConfig(processor_model="preemptive", workers=1),
               listeners=[listener], seed=seed).run(until=until)
    return listener.workflows["job"].responses


def batch_interval(values: list[float], statistic, batches: int = 20) -> tuple[float, float]:
    size = len(values) // batches
    estimates = [statistic(values[i * size:(i + 1) * size]) for i in range(batches)]
    mean = sum(estimates) / batches
    sd = math.sqrt(sum((e - mean) ** 2 for e in estimates) / (batches - 1))
    half = student_t.ppf(0.995, batches - 1) * sd / math.sqrt(batches)
    return mean - half, mean + half


def quantile(q: float):
    return lambda values: sorted(values)[math.ceil(q * len(values)) - 1]


def test_exponential_execution_times_match_the_d_m_1_closed_form(tmp_path: Path) -> None:
    mu = 1 / MEAN_S
    sigma = brentq(lambda s: s - math.exp(-mu * PERIOD_S * (1 - s)), 1e-12, 1 - 1e-12)
    rate = mu * (1 - sigma)
    assert 1 / rate == pytest.approx(1.3133, abs=1e-4)     # rho = 0.7
    values = responses(spec(tmp_path, f"exponential(mean={MEAN_S})"), until=40_000.5)
    assert len(values) >= 39_990                           # a few still queued at the end
    low, high = batch_interval(values, lambda v: sum(v) / len(v))
    assert low <= 1 / rate <= high, (low, 1 / rate, high)
    for q in (0.5, 0.9, 0.99):
        low, high = batch_interval(values, quantile(q))
        assert low <= -math.log(1 - q) / rate <= high, (q, low, high)


def test_constant_execution_time_is_not_a_queue(tmp_path: Path) -> None:
    """The same workflow with a constant 0.7 s never waits (D/D/1): every response is 0.7 s;
    and a distribution draws the same values for the same seed, others for another seed."""
    assert responses(spec(tmp_path, "PT0.7S"), until=50.5) == pytest.approx([0.7] * 50)
    path = spec(tmp_path, "uniform(min=0.2, max=0.6)")
    first, again, other = (responses(path, 50.5, 0), responses(path, 50.5, 0),
                           responses(path, 50.5, 1))
    assert first == again and first != other
    assert all(0.2 <= v <= 0.6 for v in first)            # uniform < T: nobody queues


def test_timing_reports_percentiles_with_intervals_and_units(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = spec(tmp_path, f"exponential(mean={MEAN_S})")
    assert main(["run", str(path), "--until", "2000.5", "--processor-model", "preemptive",
                 "--timing", "--json"]) == 0
    timing = json.loads(capsys.readouterr().out)["timing"]["job"]
    for name in ("response_p50", "response_p90", "response_p99"):
        low, high = timing[f"{name}_ci_s"]
        assert low <= timing[f"{name}_s"] <= high
    assert timing["response_p50_s"] < timing["response_p90_s"] < timing["response_p99_s"]
    assert timing["miss_rate"] == 0 and 0 < timing["miss_rate_ci"][1] < 0.01
    assert main(["run", str(path), "--until", "200.5", "--processor-model", "preemptive",
                 "--timing", "--timeline", "none"]) == 0
    out = capsys.readouterr().out
    assert "times in milliseconds of simulated time" in out
    assert "p50 " in out and "p90 " in out and "p99 " in out


def test_the_analysis_uses_a_bounded_distribution_s_maximum_and_no_bound_otherwise(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bounded = spec(tmp_path, "uniform(min=0.2, max=0.6)")
    assert main(["check", str(bounded), "--schedulability", "--json"]) == 0
    [row] = next(json.loads(line) for line in capsys.readouterr().out.splitlines()
             if "schedulability" in line)["schedulability"]
    assert (row["demand_s"], row["analysis_s"], row["demand_unbounded"]) == (0.6, 0.6, False)
    unbounded = spec(tmp_path, "exponential(mean=0.7)")
    assert main(["check", str(unbounded), "--schedulability", "--json"]) == 0
    [row] = next(json.loads(line) for line in capsys.readouterr().out.splitlines()
             if "schedulability" in line)["schedulability"]
    assert row["analysis_s"] is None and row["demand_unbounded"] is True
