"""Every relative link in README.md and docs/*.md leads somewhere: the file exists and, for a
``#fragment`` into a Markdown page, that page has a heading GitHub turns into that anchor.

GitHub's anchor of a heading: the text without Markdown (code ticks, link targets), lower
case, every character that is not a letter, digit, space, ``-`` or ``_`` dropped, each space
a ``-``; a repeated anchor gets ``-1``, ``-2``… So ``### Cross-validation: `opspec fit …
--holdout K``` is ``#cross-validation-opspec-fit----holdout-k`` (the ``…`` drops out between
two spaces).
"""

from __future__ import annotations

import re
import unicodedata
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
LINK = re.compile(r"\]\((?P<target>[^)\s]+)(?:\s+\"[^\"]*\")?\)")
HTML_ANCHOR = re.compile(r'<a\s+(?:name|id)="([^"]+)"')


def github_anchor(heading: str) -> str:
    text = heading.replace("`", "")
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text).strip().lower()
    kept = "".join(
        ch for ch in text
        if ch in "-_ " or unicodedata.category(ch)[0] in "LN"
    )
    return kept.replace(" ", "-")


def prose_lines(page: Path) -> list[tuple[int, str]]:
    """The page's lines outside fenced blocks, numbered from 1."""
    lines, fenced = [], False
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced:
            lines.append((number, line))
    return lines


@cache
def anchors(page: Path) -> frozenset[str]:
    found: set[str] = set()
    seen: dict[str, int] = {}
    for _, line in prose_lines(page):
        found.update(HTML_ANCHOR.findall(line))
        heading = HEADING.match(line)
        if not heading:
            continue
        anchor = github_anchor(heading.group(1))
        if anchor in seen:
            seen[anchor] += 1
            found.add(f"{anchor}-{seen[anchor]}")
        else:
            seen[anchor] = 0
            found.add(anchor)
    return frozenset(found)


def broken_links(page: Path) -> list[str]:
    broken = []
    for number, line in prose_lines(page):
        for match in LINK.finditer(re.sub(r"`[^`]*`", "", line)):
            target = match.group("target")
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, mailto: …
                continue
            path, _, fragment = target.partition("#")
            linked = (page.parent / path).resolve() if path else page
            where = f"{page.relative_to(ROOT)}:{number}: {target}"
            if not linked.exists():
                broken.append(f"{where}: no such file")
            elif fragment and linked.suffix == ".md" and fragment not in anchors(linked):
                broken.append(f"{where}: no heading with that anchor")
    return broken


def test_github_anchor_follows_githubs_rules() -> None:
    assert github_anchor("A study: `opspec study PROTOCOL.toml`") == (
        "a-study-opspec-study-protocoltoml")
    assert github_anchor("Cross-validation: `opspec fit … --holdout K`") == (
        "cross-validation-opspec-fit----holdout-k")


@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_relative_links_lead_somewhere(page: Path) -> None:
    assert broken_links(page) == []
