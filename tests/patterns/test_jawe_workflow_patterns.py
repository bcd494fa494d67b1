"""The JaWE workflow_patterns file of the corpus (``jawe10__workflow_patterns.xpdl``, by Sasa
Bojanic, Enhydra) runs every one of its processes to completion (issue 16).

Its activities are JaWE work items whose performer may update ``whereToGo``, the variable that
steers every process; here the run fixes it in advance (package data ``params``): "D" leaves
the arbitrary cycle (C goes to D unless whereToGo is "B", D to E unless it is "C") and takes no
branch of WfSP2's conditional AND split, which the file's own description says must then end
"implicitly terminated, because there's nothing else to do"; "BC" takes both of WfSP2's
branches, whose next conditions (whereToGo == "D" / "E") then fail, again leaving nothing to do.
BPMN 2.0 (section 13.3.3) would instead raise an exception when no condition of an inclusive
split holds; the issue asks this file to run to completion, so the Shark semantics its author
wrote down are the expectation. The run is bounded by ``until`` (and the engine's zero-time cycle detector).

The work items (``Implementation/No``, performed by the ROLE participant "test", each described
"Just press 'Complete' button") are manual work, XPDL 2.1 §7.6.5.1: an activity with no
implementation is "implemented by manual procedures". The run binds a performer to "test" that
completes each one as soon as it is offered, as the file's tester pressing Complete would.
"""

from __future__ import annotations

from functools import cache

import pytest
from pattern_paths import CORPUS
from patternlib import dump, outcomes, run

from opspec.engine.builtin_performers import SimulatedDevice

FILE = CORPUS / "jawe10__workflow_patterns.xpdl"
PROCESSES = [
    "WfBCP1_Sequence", "WfBCP2_Parallel_Split", "WfBCP3_Synchronization",
    "WfBCP4_Exclusive_Choice", "WfBCP5_Simple_Merge", "WfABSP1_Multiple_Choice",
    "WfABSP2_Synchronizing_Merge", "WfABSP3_Multiple_Merge", "WfABSP4_Discriminator",
    "WfABSP5_N_out_of_M_Join", "WfSP1_Arbitrary_Cycles", "WfSP2_Implicit_Termination",
    "WfPIMI1_MI_without_synchronization",
    "WfPIMI2_MI_with_a_priori_known_design_time_knowledge",
]


@cache
def _run(where_to_go: str):  # type: ignore[no-untyped-def]
    return run(FILE, until=3600, params={"whereToGo": where_to_go},
               performers={"test": SimulatedDevice()})


@pytest.mark.skipif(not FILE.exists(), reason="shared corpus not present (../shared/corpus/xpdl)")
@pytest.mark.parametrize("where_to_go", ["D", "BC"])
@pytest.mark.parametrize("process", PROCESSES)
def test_every_process_of_the_jawe_patterns_file_completes(process: str, where_to_go: str) -> None:
    result = _run(where_to_go)
    got = outcomes(result, process)
    assert got == ["completed"], f"{process}: {got}\n" + "\n".join(
        line for line in dump(result).splitlines() if process in line)


@pytest.mark.skipif(not FILE.exists(), reason="shared corpus not present (../shared/corpus/xpdl)")
@pytest.mark.parametrize("where_to_go", ["D", "BC"])
def test_the_jawe_subflow_instances_all_complete(where_to_go: str) -> None:
    got = outcomes(_run(where_to_go), "WfPIMI_Subflow")
    assert got and set(got) == {"completed"}, got
