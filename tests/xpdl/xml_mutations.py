"""Structural edits of a parsed XML tree, shared by the loader and command-line fuzz tests."""

from __future__ import annotations

import copy

from lxml import etree

__all__ = ["mutate_element"]


def mutate_element(root: etree._Element, action: str, where: float) -> None:
    """Edit the element at fraction ``where`` (0 <= where < 1) of ``root``'s descendants:
    ``delete`` it, ``duplicate`` it, ``strip`` its attributes, give it ``id`` "x", or (any
    other action) replace its text with junk. Nothing happens when ``root`` has no children."""
    elements = [e for e in root.iter() if isinstance(e.tag, str) and e is not root]
    if not elements:
        return
    element = elements[int(where * len(elements))]
    parent = element.getparent()
    if action == "delete" and parent is not None:
        parent.remove(element)
    elif action == "duplicate":
        element.addnext(copy.deepcopy(element))
    elif action == "strip":
        for key in list(element.attrib):
            del element.attrib[key]
    elif action == "id":
        element.set("Id", "x")
    else:
        element.text = "@@ not & valid ( ] {"
