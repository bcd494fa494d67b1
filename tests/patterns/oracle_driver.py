"""Run one process of an XPDL file through shoobx.wfmc (the reference Python XPDL engine) with
automatic participants and applications, and print what it executed as JSON.

Run inside the oracle venv (scripts/oracle-venv.sh), never inside opspec's:

    .oracle-venv/bin/python tests/patterns/oracle_driver.py '{"file": "x.xpdl", "process": "p"}'

Input (one JSON argument): ``file``, ``process``, ``args`` (the process's IN parameters, in
order), ``outputs`` ({application or activity id: {OUT parameter: value}}; an OUT parameter not
given is set to null). Every work item completes as soon as it starts. Output: ``{"started":
[activity ids in start order], "finished": [...], "process_finished": bool, "error": str|null,
"data": {workflow-relevant data}}``.
"""

from __future__ import annotations

import json
import sys


def main() -> int:
    spec = json.loads(sys.argv[1])
    import zope.component
    import zope.event
    import zope.interface
    from shoobx.wfmc import interfaces, process, xpdl
    from shoobx.wfmc.attributeintegration import AttributeIntegration

    with open(spec["file"]) as handle:
        package = xpdl.read(handle)
    outputs = spec.get("outputs", {})
    started: list[str] = []
    finished: list[str] = []

    def listen(event: object) -> None:
        if isinstance(event, process.ActivityStarted):
            started.append(event.activity.activity_definition_identifier)
        elif isinstance(event, process.ActivityFinished):
            finished.append(event.activity.activity_definition_identifier)

    zope.event.subscribers.append(listen)

    class Participant:
        def __init__(self, activity: object, proc: object) -> None:
            self.activity = activity

    @zope.interface.implementer(interfaces.IWorkItem)
    class AutoWorkItem:
        id = None

        def __init__(self, participant: object, proc: object, activity: object,
                     application: str) -> None:
            self.activity = activity
            self.application = application
            self.proc = proc

        def start(self, args: dict) -> None:
            act_id = self.activity.activity_definition_identifier
            app = self.proc.definition.applications.get(self.application)
            result = {}
            for parameter in getattr(app, "parameters", ()):
                if parameter.output:
                    given = {**outputs.get(self.application, {}), **outputs.get(act_id, {})}
                    result[parameter.__name__] = given.get(parameter.__name__)
            self.activity.workItemFinished(self, result)

    class Integration(AttributeIntegration):
        def createParticipant(self, activity, proc, performer):  # noqa: N802
            return Participant(activity, proc)

        def createWorkItem(self, participant, proc, activity, application):  # noqa: N802
            return AutoWorkItem(participant, proc, activity, application)

    integration = Integration()
    factory = process.StaticProcessDefinitionFactory()
    for definition in package.values():
        definition.integration = integration
        factory.register(definition)
    zope.component.provideUtility(factory)
    zope.component.provideAdapter(process.PythonExpressionEvaluator)
    proc = package[spec["process"]](None)
    error = None
    try:
        proc.start(*spec.get("args", []))
    except Exception as exc:  # the oracle's own failure is reported, not raised
        error = f"{type(exc).__name__}: {exc}"
    data = {k: v for k, v in vars(proc.workflowRelevantData).items()
            if not k.startswith("_") and isinstance(v, (str, int, float, bool, type(None)))}
    print(json.dumps({"started": started, "finished": finished,
                      "process_finished": bool(proc.isFinished), "error": error, "data": data}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
