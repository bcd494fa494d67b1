"""Read by pytest for every test of this checkout (tests/ and specs/tests alike)."""

from __future__ import annotations

import importlib.util

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    # pyproject.toml sets pytest-asyncio's fixture loop scope for the suite's Textual tests.
    # With the README's first command alone (no test extras), pytest-asyncio is not installed
    # and pytest would warn of an unknown option in every run of the spec tests of specs/tests.
    if importlib.util.find_spec("pytest_asyncio") is None:
        parser.addini("asyncio_default_fixture_loop_scope",
                      "pytest-asyncio's fixture loop scope (pytest-asyncio is not installed)")
