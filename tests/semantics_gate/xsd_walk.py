"""Every (element, attribute) an XSD declares, read with lxml: what the completeness test of
the construct registry walks. Element declarations (global and local, anonymous types or
named ones) are followed through complexContent extension and restriction, attribute groups
and attribute refs, so an attribute a base type declares (``startQuantity`` on ``tActivity``)
is listed for every element whose type derives from it."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

XS = "http://www.w3.org/2001/XMLSchema"


def _q(local: str) -> str:
    return f"{{{XS}}}{local}"


class Schema:
    """The named types, elements and attribute groups of a set of XSD files that share a
    target namespace (``include`` as Semantic.xsd is included by BPMN20.xsd)."""

    def __init__(self, *files: Path) -> None:
        self.types: dict[str, etree._Element] = {}
        self.elements: dict[str, etree._Element] = {}
        self.groups: dict[str, etree._Element] = {}
        self.attribute_groups: dict[str, etree._Element] = {}
        self.namespace = ""
        for file in files:
            root = etree.parse(str(file)).getroot()
            self.namespace = root.get("targetNamespace") or self.namespace
            for child in root:
                name = child.get("name")
                if child.tag in (_q("complexType"), _q("simpleType")):
                    self.types[name] = child
                elif child.tag == _q("element"):
                    self.elements[name] = child
                elif child.tag == _q("group"):
                    self.groups[name] = child
                elif child.tag == _q("attributeGroup"):
                    self.attribute_groups[name] = child

    @staticmethod
    def _local(ref: str) -> str:
        return ref.rsplit(":", 1)[-1]

    def attributes_of_type(self, type_element: etree._Element, seen: frozenset[str] = frozenset()
                           ) -> set[str]:
        out: set[str] = set()
        for node in type_element.iter(_q("attribute"), _q("attributeGroup"), _q("extension"),
                                      _q("restriction")):
            # only this type's own declarations: skip those of nested element declarations
            if self._owner(node) is not type_element:
                continue
            if node.tag == _q("attribute"):
                name = node.get("name") or node.get("ref")
                if name:
                    out.add(self._local(name))
            elif node.tag == _q("attributeGroup") and node.get("ref"):
                group = self.attribute_groups.get(self._local(node.get("ref")))
                if group is not None:
                    out |= self.attributes_of_type(group, seen)
            elif node.get("base"):
                base = self._local(node.get("base"))
                if base in self.types and base not in seen:
                    out |= self.attributes_of_type(self.types[base], seen | {base})
        return out

    @staticmethod
    def _owner(node: etree._Element) -> etree._Element | None:
        """The complexType, attributeGroup or element whose declaration ``node`` belongs to."""
        parent = node.getparent()
        while parent is not None and parent.tag not in (_q("complexType"),
                                                        _q("attributeGroup")):
            parent = parent.getparent()
        return parent

    def abstract(self, element: etree._Element) -> bool:
        """An abstract element, or one of an abstract type: never written in a file (its
        concrete substitutes carry its attributes)."""
        if element.get("abstract") == "true":
            return True
        named = self.types.get(self._local(element.get("type") or ""))
        return named is not None and named.get("abstract") == "true"

    def pairs(self) -> set[tuple[str, str | None]]:
        """``(element, None)`` for every element declared, and ``(element, attribute)`` for
        every attribute its type has."""
        out: set[tuple[str, str | None]] = set()
        declarations = [e for root_element in self.elements.values()
                        for e in root_element.iter(_q("element"))]
        for named in self.types.values():
            declarations.extend(named.iter(_q("element")))
        for group in self.groups.values():
            declarations.extend(group.iter(_q("element")))
        for element in declarations:
            name = element.get("name")
            if name is None or self.abstract(element):
                continue            # a ref (listed where declared), or abstract (never written)
            out.add((name, None))
            complex_type = element.find(_q("complexType"))
            if complex_type is None and element.get("type"):
                complex_type = self.types.get(self._local(element.get("type")))
            if complex_type is not None and complex_type.tag == _q("complexType"):
                for attribute in self.attributes_of_type(complex_type):
                    out.add((name, attribute))
        return out
