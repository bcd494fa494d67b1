"""Hardware in the loop: the dispenser's alarm on a real board.

Run it with the board plugged in (the firmware must speak ``devices/medication_dispenser.toml``)::

    pytest tests/bindings/test_hardware.py -m hardware --device-url=/dev/ttyACM0

``--device-profile`` picks another profile. The same test also runs against an emulator, which
is how it is kept working without hardware::

    opspec devices emulate medication_dispenser --port pty      # prints /dev/pts/N
    pytest tests/bindings/test_hardware.py -m hardware --device-url=/dev/pts/N

The test switches the alarm on and off (nothing is dispensed) and checks the replies came
within the profile's timeout, with no fault.
"""

from __future__ import annotations

import pytest

from opspec.bindings import bind, resolve_profile
from opspec.bindings.profiles import DeviceProfile

from .conftest import DEVICES
from .fakes import FakeSession, item, run_until

pytestmark = pytest.mark.hardware


@pytest.fixture
def device(request: pytest.FixtureRequest) -> tuple[str, DeviceProfile]:
    url = request.config.getoption("--device-url")
    if not url:
        pytest.skip("needs a real device: run `pytest tests/bindings/test_hardware.py "
                    "-m hardware --device-url=/dev/ttyUSB0` (see this file's docstring)")
    return url, resolve_profile(request.config.getoption("--device-profile"), DEVICES)


def test_alarm_switches_on_and_off_on_the_real_device(
        device: tuple[str, DeviceProfile]) -> None:
    url, profile = device
    if "alarm_on" not in profile.operations or "alarm_off" not in profile.operations:
        pytest.skip(f"profile {profile.name} has no alarm_on/alarm_off operations")
    session = FakeSession()
    with bind(profile.participants[0], url, profile) as binding:  # waits settle_ms
        binding.attach(session)
        on, off = item("alarm_on", profile.participants[0]), \
            item("alarm_off", profile.participants[0])
        binding.offer(on)
        binding.offer(off)
        run_until(binding.inbox, session, lambda: len(session.answered) == 2, timeout=30)
    assert session.faults() == []
    assert session.completed == [(on, None), (off, None)]
    summary = binding.latency_summary()
    print(f"\n{profile.name} on {url}: round trip {summary.describe()}")
    assert summary.max < profile.operations["alarm_on"].timeout_s
