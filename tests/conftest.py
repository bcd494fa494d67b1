"""Options shared by the whole test suite.

``--device-url`` (and ``--device-profile``) run the hardware-in-the-loop tests marked
``@pytest.mark.hardware`` against a real device: ``pytest --device-url=/dev/ttyUSB0 -m hardware``.
Without ``--device-url`` those tests are skipped with a message saying how to run them.
"""

from __future__ import annotations

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("opspec hardware", "hardware-in-the-loop tests")
    group.addoption("--device-url", default=None, metavar="URL",
                    help="serial port or pySerial URL of a real device for tests marked "
                    "'hardware' (e.g. /dev/ttyUSB0, /dev/ttyACM0, rfc2217://host:port)")
    group.addoption("--device-profile", default="medication_dispenser", metavar="NAME",
                    help="device profile (name in devices/ or .toml path) of that device")
