"""Options shared by the whole test suite come from the opspec pytest plugin
(``opspec.testing.plugin``, registered through the ``pytest11`` entry point).

``--device-url`` (and ``--device-profile``) run the hardware-in-the-loop tests marked
``@pytest.mark.hardware`` against a real device: ``pytest --device-url=/dev/ttyUSB0 -m hardware``.
Without ``--device-url`` those tests are skipped with a message saying how to run them.
"""

import os

import pytest


@pytest.fixture(autouse=True)
def _inner_pytest_runs_leave_the_snapshot_plugin_alone(request: pytest.FixtureRequest,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """pytester runs pytest in this process; pytest-textual-snapshot keeps its temporary
    folder's name in the environment, replaces it when a session starts and deletes it when
    that session ends, so an inner run would leave the outer session pointing at a deleted
    folder. Putting the outer value back after each pytester test keeps the outer one."""
    if "pytester" in request.fixturenames and "TEXTUAL_SNAPSHOT_TEMPDIR" in os.environ:
        monkeypatch.setenv("TEXTUAL_SNAPSHOT_TEMPDIR", os.environ["TEXTUAL_SNAPSHOT_TEMPDIR"])


@pytest.fixture
def load_benchmark():
    """``load_benchmark("interval_coverage")``: the module ``benchmarks/<name>.py`` (a script,
    not a package), for the tests that run a benchmark's own measurement."""
    import importlib.util
    from pathlib import Path

    folder = Path(__file__).resolve().parents[1] / "benchmarks"

    def load(name: str):
        spec = importlib.util.spec_from_file_location(f"benchmark_{name}", folder / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load


@pytest.fixture
def no_report():
    """`opspec evaluate` in this test draws no report (tests/evaluate_without_report.py):
    for a test that reads the store, ``--json`` or an export, and not the report."""
    from evaluate_without_report import without_report

    with without_report():
        yield


#: the names a Chromium (or Chrome) executable goes by
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


@pytest.fixture(scope="session")
def chromium() -> str:
    """A headless-capable Chromium for the tests that look at opspec's output in a real
    browser (the report, a study served over HTTP): found on PATH, else installed by
    ``scripts/system-deps.sh`` (the project's own files install what a test needs), else the
    test is skipped saying why."""
    import shutil
    import subprocess
    from pathlib import Path

    def find() -> str | None:
        return next((found for name in CHROMIUM_NAMES if (found := shutil.which(name))), None)

    found = find()
    if found is None:
        script = Path(__file__).resolve().parents[1] / "scripts" / "system-deps.sh"
        subprocess.run(["bash", str(script)], check=False, capture_output=True, timeout=900)
        found = find()
    if found is None:
        pytest.skip("no Chromium and it cannot be installed here (scripts/system-deps.sh "
                    "needs root or passwordless sudo and apt-get)")
    return found


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The tests marked ``slow`` (tens of seconds each) run first. On xdist's workers
    (`-n auto --dist worksteal`, scripts/test.sh) each worker starts with its share of the
    collection in order and an idle worker takes from the end of another's: with the long
    tests at the front, the last tests left are short ones and the workers finish together,
    instead of one worker running a long test alone at the end. Otherwise the order is
    kept (a module's tests stay together, so its module fixtures are made once)."""
    slow = [item for item in items if item.get_closest_marker("slow") is not None]
    if slow:
        chosen = set(map(id, slow))
        items[:] = slow + [item for item in items if id(item) not in chosen]
