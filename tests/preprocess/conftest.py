"""Fixtures of the writer and preprocessor tests."""

from __future__ import annotations

import pytest
from builtin_models import SCHEMA_PATH
from lxml import etree


@pytest.fixture(scope="session")
def xpdl_schema() -> etree.XMLSchema:
    """The official XPDL 2.1 schema, loaded from local files only (it imports the 1.0 schema
    from the same folder; no network)."""
    return etree.XMLSchema(etree.parse(str(SCHEMA_PATH), etree.XMLParser(no_network=True)))
