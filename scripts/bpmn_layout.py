"""Add diagram interchange (BPMNDI) to a BPMN 2.0 file that has none, laid out by Graphviz,
so that bpmn.io and Camunda Modeler open it (they draw only what BPMNDI places).

    python scripts/bpmn_layout.py IN.bpmn OUT.bpmn

Each pool's process is laid out left to right by ``dot`` (its flow nodes as boxes of BPMN's
usual sizes, its sequence flows as edges, boundary events through their host); pools are
stacked top to bottom, a pool with one lane gets a lane as wide as the pool; boundary events
sit on the lower edge of their host; message flows go straight from pool to pool. Sequence
flows follow dot's splines (every third control point). Used to draw
specs/medication_dispenser.bpmn; it makes a diagram that opens, not a beautiful one.
Needs the ``dot`` program (Graphviz).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from lxml import etree

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"
BPMNDI = "http://www.omg.org/spec/BPMN/20100524/DI"
DC = "http://www.omg.org/spec/DD/20100524/DC"
DI = "http://www.omg.org/spec/DD/20100524/DI"
SIZES = {"Event": (36, 36), "Gateway": (50, 50)}
TASK = (100, 80)
POOL_HEADER = 30           # the pool's name band on its left
LANE_HEADER = 30
MARGIN = 40


def _b(name: str) -> str:
    return f"{{{BPMN}}}{name}"


def _size(element: etree._Element) -> tuple[int, int]:
    name = etree.QName(element).localname
    for suffix, size in SIZES.items():
        if name.endswith(suffix):
            return size
    return TASK


def _layout(process: etree._Element) -> tuple[dict[str, tuple[float, float, int, int]],
                                              dict[str, list[tuple[float, float]]],
                                              float, float]:
    """Node boxes (x, y, w, h; top-left), edge waypoints, and the width and height used."""
    nodes = {}
    boundary = {}
    for element in process:
        if not isinstance(element.tag, str) or etree.QName(element).namespace != BPMN:
            continue
        name = etree.QName(element).localname
        if name in ("sequenceFlow", "laneSet", "extensionElements", "documentation"):
            continue
        if name == "boundaryEvent":
            boundary[element.get("id")] = element.get("attachedToRef")
            continue
        nodes[element.get("id")] = element
    lines = ["digraph G {", "rankdir=LR; nodesep=0.5; ranksep=0.6; splines=polyline;",
             "node [shape=box, fixedsize=true, label=\"\"];"]
    for node_id, element in nodes.items():
        width, height = _size(element)
        lines.append(f'"{node_id}" [width={width / 72:.3f}, height={height / 72:.3f}];')
    flows = []
    for flow in process.iter(_b("sequenceFlow")):
        source, target = flow.get("sourceRef"), flow.get("targetRef")
        tail = boundary.get(source, source)
        if tail in nodes and target in nodes:
            flows.append(flow.get("id"))
            lines.append(f'"{tail}" -> "{target}" [id="{flow.get("id")}"];')
    lines.append("}")
    result = subprocess.run(["dot", "-Tjson"], input="\n".join(lines), capture_output=True,
                            text=True, check=True)
    graph = json.loads(result.stdout)
    _x0, _y0, width, height = (float(v) for v in graph["bb"].split(","))
    boxes = {}
    for obj in graph.get("objects", []):
        if obj.get("name") in nodes:
            cx, cy = (float(v) for v in obj["pos"].split(","))
            w, h = _size(nodes[obj["name"]])
            boxes[obj["name"]] = (cx - w / 2, height - cy - h / 2, w, h)
    for event_id, host in boundary.items():
        if host in boxes:
            hx, hy, hw, hh = boxes[host]
            others = [b for b, h in boundary.items() if h == host]
            index = others.index(event_id)
            boxes[event_id] = (hx + hw - 28 - 38 * index, hy + hh - 18, 36, 36)
    edges = {}
    for edge in graph.get("edges", []):
        points = []
        end = None
        for part in edge["pos"].split():
            if part.startswith(("e,", "s,")):
                x, y = part[2:].split(",")
                if part.startswith("e,"):
                    end = (float(x), height - float(y))
                continue
            x, y = part.split(",")
            points.append((float(x), height - float(y)))
        waypoints = points[::3] + ([points[-1]] if (len(points) - 1) % 3 else [])
        if end is not None:
            waypoints.append(end)
        edges[edge["id"]] = waypoints
    return boxes, edges, width, height


def _shape(plane: etree._Element, element_id: str, x: float, y: float, w: float, h: float,
           **extra: str) -> None:
    shape = etree.SubElement(plane, f"{{{BPMNDI}}}BPMNShape", id=f"{element_id}_di",
                             bpmnElement=element_id, **extra)
    etree.SubElement(shape, f"{{{DC}}}Bounds", x=f"{x:.0f}", y=f"{y:.0f}", width=f"{w:.0f}",
                     height=f"{h:.0f}")


def _edge(plane: etree._Element, element_id: str, points: list[tuple[float, float]]) -> None:
    edge = etree.SubElement(plane, f"{{{BPMNDI}}}BPMNEdge", id=f"{element_id}_di",
                            bpmnElement=element_id)
    for x, y in points:
        etree.SubElement(edge, f"{{{DI}}}waypoint", x=f"{x:.0f}", y=f"{y:.0f}")


def add_diagram(root: etree._Element) -> None:
    """Append a BPMNDiagram for the first collaboration of ``root`` (every pool, lane, flow
    node, sequence flow and message flow gets a shape or an edge)."""
    collaboration = root.find(_b("collaboration"))
    if collaboration is None:
        raise SystemExit("the file has no collaboration (pools) to lay out")
    processes = {p.get("id"): p for p in root.iter(_b("process"))}
    diagram = etree.SubElement(root, f"{{{BPMNDI}}}BPMNDiagram", id="diagram")
    plane = etree.SubElement(diagram, f"{{{BPMNDI}}}BPMNPlane", id="plane",
                             bpmnElement=collaboration.get("id"))
    centres: dict[str, tuple[float, float, float, float]] = {}
    layouts = []
    widest = 0.0
    for participant in collaboration.iter(_b("participant")):
        process = processes[participant.get("processRef")]
        boxes, edges, width, height = _layout(process)
        lanes = list(process.iter(_b("lane")))
        if len(lanes) > 1:
            raise SystemExit(f"pool {participant.get('id')}: more than one lane is not laid out")
        layouts.append((participant, process, boxes, edges, height, lanes))
        widest = max(widest, width)
    top = 0.0
    for participant, process, boxes, edges, height, lanes in layouts:
        left = POOL_HEADER + (LANE_HEADER if lanes else 0) + MARGIN
        pool_height = height + 2 * MARGIN
        pool_width = widest + POOL_HEADER + LANE_HEADER + 2 * MARGIN
        _shape(plane, participant.get("id"), 0, top, pool_width, pool_height, isHorizontal="true")
        for lane in lanes:
            _shape(plane, lane.get("id"), POOL_HEADER, top, pool_width - POOL_HEADER,
                   pool_height, isHorizontal="true")
        for node_id, (x, y, w, h) in boxes.items():
            _shape(plane, node_id, left + x, top + MARGIN + y, w, h)
            centres[node_id] = (left + x, top + MARGIN + y, w, h)
        for flow_id, points in edges.items():
            _edge(plane, flow_id, [(left + x, top + MARGIN + y) for x, y in points])
        centres[participant.get("id")] = (0, top, pool_width, pool_height)
        top += pool_height + MARGIN
    for flow in collaboration.iter(_b("messageFlow")):
        sx, sy, sw, sh = centres[flow.get("sourceRef")]
        tx, ty, tw, th = centres[flow.get("targetRef")]
        start_x, end_x = sx + sw / 2, tx + tw / 2
        if sy < ty:
            points = [(start_x, sy + sh), (start_x, (sy + sh + ty) / 2),
                      (end_x, (sy + sh + ty) / 2), (end_x, ty)]
        else:
            points = [(start_x, sy), (start_x, (sy + ty + th) / 2),
                      (end_x, (sy + ty + th) / 2), (end_x, ty + th)]
        _edge(plane, flow.get("id"), points)


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    source, target = Path(argv[0]), Path(argv[1])
    parser = etree.XMLParser(resolve_entities=False, no_network=True, remove_blank_text=False)
    tree = etree.parse(str(source), parser)
    for old in tree.getroot().findall(f"{{{BPMNDI}}}BPMNDiagram"):
        tree.getroot().remove(old)
    add_diagram(tree.getroot())
    etree.indent(tree.getroot().find(f"{{{BPMNDI}}}BPMNDiagram"), space="  ", level=1)
    tree.getroot().find(f"{{{BPMNDI}}}BPMNDiagram").tail = "\n"
    tree.write(str(target), xml_declaration=True, encoding="UTF-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
