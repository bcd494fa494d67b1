"""Property-based robustness: mutated corpus files never make the loader raise or hang; they
give a package or diagnostics (issue 2, "Bad input")."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree
from xml_mutations import mutate_element

from opspec.xpdl import LoadResult, parse_bytes

CORPUS = Path("/work/shared/corpus/xpdl")
SAMPLES = sorted(CORPUS.glob("*.xpdl"))[::4] if CORPUS.is_dir() else []
SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
SOURCES = [SPEC, *SAMPLES]
DATA = {path.name: path.read_bytes() for path in SOURCES}

FUZZ = settings(max_examples=25, deadline=2000, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def check(result: LoadResult) -> None:
    assert result.package is not None or result.diagnostics
    assert "internal-error" not in [d.code for d in result.diagnostics], result.diagnostics
    for diagnostic in result.diagnostics:
        assert diagnostic.location.path
        str(diagnostic)


names = st.sampled_from(sorted(DATA))


def _well_formed(data: bytes) -> bool:
    try:
        etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        return False
    return True


# structural mutations start from a parsed tree: only the files that are well-formed (the
# corpus keeps one that is not, for the reader tests)
well_formed = st.sampled_from(sorted(n for n, data in DATA.items() if _well_formed(data)))


@pytest.mark.skipif(not SAMPLES, reason="shared corpus not present")
@FUZZ
@given(name=names, flips=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)),
                                  min_size=1, max_size=8))
def test_byte_flips_never_crash(name: str, flips: list[tuple[float, int]]) -> None:
    data = bytearray(DATA[name])
    for where, value in flips:
        data[int(where * len(data))] = value
    check(parse_bytes(bytes(data), path=name))


@pytest.mark.skipif(not SAMPLES, reason="shared corpus not present")
@FUZZ
@given(name=names, cut=st.floats(0, 1))
def test_truncation_never_crashes(name: str, cut: float) -> None:
    data = DATA[name]
    check(parse_bytes(data[: int(cut * len(data))], path=name))


@pytest.mark.skipif(not SAMPLES, reason="shared corpus not present")
@FUZZ
@given(name=well_formed, edits=st.lists(st.tuples(st.sampled_from(["delete", "duplicate", "strip", "text"]),
                                            st.floats(0, 1, exclude_max=True)),
                                  min_size=1, max_size=6))
def test_structural_mutations_never_crash(name: str, edits: list[tuple[str, float]]) -> None:
    root = etree.fromstring(DATA[name], etree.XMLParser(resolve_entities=False, no_network=True))
    for action, where in edits:
        mutate_element(root, action, where)
    check(parse_bytes(etree.tostring(root), path=name))
