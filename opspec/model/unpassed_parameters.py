"""The IN parameters nothing passes: a process no SubFlow calls runs on its own (opspec
starts its instances: auto-started, or by its start events' triggers), and an instance
started so has no invoker to give its IN and INOUT formal parameters their values. XPDL
leaves those values to the invoker (WfMC's createProcessInstance, or a SubFlow's actual
parameters); opspec starts such an instance with the parameter null, unless a DataField of
the same Id gives it its initial value (:func:`opspec.model.checks._parameter_fields`). A
condition that reads a null fails at run time, so ``opspec validate`` says it at the
parameter.
"""

from __future__ import annotations

from collections.abc import Mapping

from opspec.model.checks_support import Reporter
from opspec.model.data import ParameterMode
from opspec.model.instance_starts import called_processes
from opspec.model.package import Package

__all__ = ["unpassed_parameters"]

_PASSED_IN = (ParameterMode.IN, ParameterMode.INOUT)


def unpassed_parameters(package: Package, packages: Mapping[str, Package],
                        report: Reporter) -> None:
    """A ``unpassed-parameter`` warning for every IN or INOUT formal parameter, without a
    DataField of its Id, of a process of ``package`` that no SubFlow of the loaded packages
    calls."""
    called = called_processes(package).union(
        *(called_processes(other) for other in packages.values() if other is not package))
    for process in package.processes:
        if process.id in called:
            continue
        defaults = {field.id for field in process.data_fields}
        for formal in process.formal_parameters:
            if formal.mode not in _PASSED_IN or formal.id in defaults:
                continue
            report.warning(
                formal, "unpassed-parameter",
                f"process {process.id!r} runs on its own (no SubFlow or call activity calls "
                "it), so nothing "
                f"passes its {formal.mode.value} parameter {formal.id!r}: every instance starts "
                "with it null, and a condition or script that reads it fails at run time",
                "make it a package data field instead (a run input: --param "
                f"{formal.id}=VALUE sets it), or call the process from a SubFlow or call "
                "activity that passes it")
