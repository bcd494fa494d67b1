"""The opspec pytest plugin (registered through the ``pytest11`` entry point ``opspec``).

Fixtures:

* ``spec`` - the :class:`~opspec.model.Package` named by ``@pytest.mark.spec("path")`` on the
  test (or its class/module), else by a module-level ``SPEC = "path"``. Paths are tried
  relative to the test file, then to pytest's rootdir. Loaded once per session per file.
* ``simulate`` - :func:`opspec.testing.simulation.simulate` with the test's seed as default
  and paths (spec, user model, script file) resolved like the marker's::

      def test_reporting_user_takes_the_dose(spec, simulate):
          result = simulate(spec, script=[("after trg_2 90s", "press_report")])
          assert result.value("doses_taken") == 4

* ``opspec_seed`` - the seed ``simulate`` uses: ``--opspec-seed`` (default 0) mixed with the
  test id, so tests are independent of each other but each is reproducible. A failing test's
  report shows it.
* ``device_url`` / ``device_profile`` - ``--device-url`` and ``--device-profile`` for
  hardware-in-the-loop tests (marked ``hardware``); ``device_url`` skips without a URL.
* ``regen_golden`` - whether ``--opspec-regen-golden`` was given (golden traces are written
  instead of compared).

Scenario files (``*.scenario.toml``, see :mod:`opspec.testing.scenario`) are collected as
tests, one item per ``[[scenario]]``. The warnings on the specs simulated, and the notes on
claims that held on replications all alike, are listed once at the end of the session
(pytest-xdist workers hand theirs to the controller).
"""

from __future__ import annotations

from collections.abc import Generator, Sequence
from pathlib import Path
from typing import Any

import pytest

from opspec.errors import OpspecError

__all__ = [
    "ScenarioFile",
    "ScenarioItem",
    "Simulator",
    "pytest_addoption",
    "pytest_collect_file",
    "pytest_configure",
    "pytest_sessionfinish",
    "pytest_terminal_summary",
    "pytest_testnodedown",
    "simulator_for",
]

_SEED_KEY = pytest.StashKey[int]()
_SPECS_KEY = pytest.StashKey[dict[Path, Any]]()
#: the front hall's warnings on what a test simulated (validate's on the spec, the user
#: model's), per test and over the session: shown in the report and at the end
_WARNED_KEY = pytest.StashKey[dict[str, None]]()
#: the notes on ``then`` lines that held on replications all alike (a mean's interval of no
#: width), per test and over the session: shown in the report and at the end
_NOTED_KEY = pytest.StashKey[dict[str, None]]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("opspec", "opspec executable specifications")
    group.addoption("--opspec-seed", type=int, default=0, metavar="N",
                    help="base seed of simulate() and scenario files; each test mixes in its "
                         "own id, so tests stay independent but reproducible (default 0)")
    group.addoption("--opspec-regen-golden", action="store_true", default=False,
                    help="write golden traces instead of comparing runs with them")
    group.addoption("--device-url", default=None, metavar="URL",
                    help="serial port or pySerial URL of a real device for tests marked "
                         "'hardware' (e.g. /dev/ttyUSB0, /dev/ttyACM0, rfc2217://host:port)")
    group.addoption("--device-profile", default="medication_dispenser", metavar="NAME",
                    help="device profile (name in devices/ or .toml path) of that device")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "spec(path): the XPDL spec the 'spec' fixture loads (relative to the test "
                   "file or the rootdir)")
    config.addinivalue_line(
        "markers", "hardware: needs a real serial device (--device-url)")
    config.stash[_SPECS_KEY] = {}
    config.stash[_WARNED_KEY] = {}
    config.stash[_NOTED_KEY] = {}


def _warned(node: pytest.Item | None, config: pytest.Config, result: Any) -> None:
    """Keep ``result``'s warnings and failed replications for the test's report (a simulated
    spec's warnings are otherwise seen by nobody: a test rarely prints them)."""
    lines = [f"warning: {w}" if "warning" not in str(w) else str(w)
             for w in getattr(result, "warnings", ())]
    for line in lines:
        config.stash[_WARNED_KEY][line] = None
    if node is not None:
        seen = node.stash.setdefault(_WARNED_KEY, {})
        for line in lines:
            seen[line] = None
        for failed in getattr(result, "failed", ()):
            seen[f"failed {failed}"] = None


def _noted(node: pytest.Item, config: pytest.Config, line: str) -> None:
    """Keep a note on a claim that held (:meth:`Expectation.caveat`) for the test's report
    and the session's end: a green test must not read as a value known exactly."""
    config.stash[_NOTED_KEY][line] = None
    node.stash.setdefault(_NOTED_KEY, {})[line] = None


# ---------------------------------------------------------------- paths and specs
def resolve_path(ref: str | Path, config: pytest.Config, near: Path | None,
                 fix: str = "") -> Path:
    """``ref`` as an existing path: absolute, else next to ``near`` (a test file), else under
    the rootdir. Fails the test with the places tried when none exists (each once: a test in
    the rootdir looks in one place), and ``fix``, what to correct, when given."""
    path = Path(ref)
    candidates = [path] if path.is_absolute() else [
        *([near.parent / path] if near is not None else []), config.rootpath / path]
    for candidate in candidates:
        if candidate.exists():
            return candidate.resolve()
    places = list(dict.fromkeys(str(candidate) for candidate in candidates))
    advice = f"; {fix}" if fix else ""
    pytest.fail(f"{ref}: file not found (looked at {', '.join(places)}){advice}",
                pytrace=False)


def load_cached(path: Path, config: pytest.Config) -> Any:
    """The package of ``path`` (XPDL, BPMN or ``.wfs``) and the spec ready to run (an
    :class:`opspec.runs.LoadedSpec`, with validate's warnings on it), loaded once per
    session; a spec ``opspec validate`` refuses fails the test with its ``path:line`` message
    (no traceback)."""
    cache = config.stash[_SPECS_KEY]
    if path not in cache:
        from opspec.runs import load

        problem = None
        try:
            # the front hall's gate: refused as `opspec validate` refuses it, any form
            loaded = load(path)
            cache[path] = (loaded.package, loaded)
        except OpspecError as error:
            problem = f"cannot load the spec: {error}"
        if problem is not None:          # outside the except: no "during handling" chain
            pytest.fail(problem, pytrace=False)
    return cache[path]


def _compiled_for(package: Any, config: pytest.Config) -> Any:
    """The loaded spec of the ``spec`` fixture's package (its warnings come with it)."""
    for cached, loaded in config.stash[_SPECS_KEY].values():
        if cached is package:
            return loaded
    return package


@pytest.fixture
def spec(request: pytest.FixtureRequest) -> Any:
    """The spec (a :class:`~opspec.model.Package`) named by ``@pytest.mark.spec("path")`` on
    the test, class or module, else by a module-level ``SPEC = "path"``: a path next to the
    test file or under the rootdir, loaded once per session; a spec ``opspec validate``
    refuses fails the test with its ``path:line`` message. Guide: docs/spec-testing.md."""
    marker = request.node.get_closest_marker("spec")
    ref: Any = None
    if marker is not None:
        if len(marker.args) != 1:
            pytest.fail("@pytest.mark.spec takes one path, e.g. "
                        "@pytest.mark.spec('specs/medication_dispenser.xpdl')", pytrace=False)
        ref = marker.args[0]
    else:
        ref = getattr(request.module, "SPEC", None) if request.module is not None else None
    if ref is None:
        pytest.fail("the 'spec' fixture needs @pytest.mark.spec('path/to/spec.xpdl') on the "
                    "test or a module-level SPEC = 'path/to/spec.xpdl'", pytrace=False)
    where = request.node.path.name if request.node.path is not None else "the test file"
    fix = (f"fix @pytest.mark.spec(...) in {where}" if marker is not None else
           f"fix SPEC = ... in {where} (a path relative to it or to the rootdir)")
    path = resolve_path(ref, request.config, request.node.path, fix)
    return load_cached(path, request.config)[0]


@pytest.fixture
def opspec_seed(request: pytest.FixtureRequest) -> int:
    """The test's seed, the one ``simulate`` uses unless given ``seed=``: ``--opspec-seed``
    (default 0) mixed with the test id, so each test draws differently and reproducibly (the
    same on every machine and number of xdist workers); a failing test's report shows it."""
    from opspec.testing.simulation import derive_seed

    seed = derive_seed(request.config.getoption("--opspec-seed"), request.node.nodeid)
    request.node.stash[_SEED_KEY] = seed
    return seed


class Simulator:
    """The ``simulate`` fixture: :func:`opspec.testing.simulation.simulate` bound to a test.

    ``seed`` defaults to the test's seed; ``spec`` may be a Package (e.g. the ``spec``
    fixture) or a path; relative paths (spec, ``user_model`` file, ``script`` file) are
    resolved next to the test file, then under the rootdir. Errors in the arguments (unknown
    activity in a script, bad user model) fail the test with opspec's message, not a
    traceback.
    """

    def __init__(self, config: pytest.Config, near: Path | None, seed: int,
                 node: pytest.Item | None = None) -> None:
        self.config = config
        self.near = near
        self.seed = seed
        self.node = node

    def __repr__(self) -> str:
        return f"<simulate fixture, seed {self.seed}>"

    def __call__(self, spec: Any = None, users: int = 1, days: float | None = None,
                 script: Any = None, user_model: Any = None, seed: int | None = None,
                 until: float | None = None, engine_config: Any = None,
                 **options: Any) -> Any:
        __tracebackhide__ = True            # a failure is the test's line, not this frame
        from opspec.testing.simulation import simulate

        if spec is None:
            pytest.fail("simulate() needs a spec: simulate(spec, ...) with the 'spec' fixture "
                        "or a path", pytrace=False)
        takes = _simulate_takes(simulate)
        unknown = [name for name in options if name not in takes]
        if unknown:
            pytest.fail(f"{self._calling_line()}{_unknown_options(unknown, takes)}",
                        pytrace=False)
        if isinstance(spec, (str, Path)):
            spec = load_cached(resolve_path(spec, self.config, self.near,
                                            "fix the spec path given to simulate()"),
                               self.config)[1]
        else:
            spec = _compiled_for(spec, self.config)
        if isinstance(user_model, Path) or (isinstance(user_model, str)
                                            and user_model.endswith(".toml")):
            user_model = resolve_path(user_model, self.config, self.near,
                                      "fix user_model= given to simulate()")
        if isinstance(script, (str, Path)):
            script = resolve_path(script, self.config, self.near,
                                  "fix script= given to simulate()")
        try:
            result = simulate(spec, users=users, days=days, script=script,
                              user_model=user_model, seed=self.seed if seed is None else seed,
                              until=until, engine_config=engine_config, **options)
        except OpspecError as error:
            problem = f"{self._calling_line()}simulate(): {error}"
        else:
            _warned(self.node, self.config, result)
            return result
        pytest.fail(problem, pytrace=False)     # outside the except: the message once

    def _calling_line(self) -> str:
        """``test_x.py:12: result = simulate(...)`` and a new line: the line of the test
        file that called (a test may simulate several times), or nothing when none did."""
        import linecache
        import sys

        frame = sys._getframe(1)
        while frame is not None:
            if self.near is not None and Path(frame.f_code.co_filename) == self.near:
                line = linecache.getline(frame.f_code.co_filename, frame.f_lineno).strip()
                return f"{self.near.name}:{frame.f_lineno}: {line}\n"
            frame = frame.f_back  # type: ignore[assignment]
        return ""


def _simulate_takes(simulate: Any) -> tuple[str, ...]:
    """The arguments of ``simulate`` (what the fixture passes on), in its order."""
    import inspect

    return tuple(inspect.signature(simulate).parameters)


def _unknown_options(unknown: Sequence[str], takes: Sequence[str]) -> str:
    """What to say of keywords ``simulate`` does not take (a misspelt ``user=`` was a
    ``TypeError`` through the plugin's frame)."""
    import difflib

    lines = []
    for name in unknown:
        close = difflib.get_close_matches(name, takes, n=1)
        lines.append(f"simulate() has no argument {name!r}"
                     + (f": did you mean {close[0]}=?" if close else ""))
    lines.append(f"it takes: {', '.join(takes)} (docs/spec-testing.md, Fixtures)")
    return "\n".join(lines)


@pytest.fixture
def simulate(request: pytest.FixtureRequest, opspec_seed: int) -> Simulator:
    """``simulate(spec, users=1, days=None, until=None, script=None, user_model=None,
    seed=None, ...)`` -> ``SimulationResult``: run ``spec`` (the ``spec`` fixture or a path)
    for ``users`` simulated users, each scripted (``script=[("after trg_2 90s",
    "press_report")]``) or drawn from a user model (``user_model="x.users.toml"``), for
    ``days`` or ``until`` seconds, seeded with the test's seed (``opspec_seed``); paths are
    next to the test file or under the rootdir. Check the result with ``expect``, ``check``
    or ``assert_rate`` (opspec.testing). Guide: docs/spec-testing.md.

    The other arguments are those of :func:`opspec.testing.simulate` (``monitors``,
    ``no_user``, ``params``, ``performers``, ``keep_trace``, ``engine_config``,
    ``branches``); see :class:`Simulator`."""
    return Simulator(request.config, request.node.path, opspec_seed, request.node)


def simulator_for(request: pytest.FixtureRequest) -> Simulator:
    """A :class:`Simulator` for a fixture of any scope (its seed mixes ``--opspec-seed`` with
    the requesting node's id), e.g. to share one expensive many-user run in a module::

        @pytest.fixture(scope="module")
        def reference_users(request):
            return simulator_for(request)(SPEC, users=600, user_model="dispenser-reference")
    """
    from opspec.testing.simulation import derive_seed

    seed = derive_seed(request.config.getoption("--opspec-seed"), request.node.nodeid)
    return Simulator(request.config, request.node.path, seed)


@pytest.fixture
def regen_golden(request: pytest.FixtureRequest) -> bool:
    """True when ``--opspec-regen-golden`` was given (golden traces are written instead of
    compared)."""
    return bool(request.config.getoption("--opspec-regen-golden"))


@pytest.fixture
def golden(request: pytest.FixtureRequest) -> Any:
    """``golden(trace_or_result, path)``: compare with a stored golden trace (written instead
    with ``--opspec-regen-golden``); ``path`` is relative to the test file."""
    try:
        from opspec.testing import golden as golden_module
    except ImportError:
        pytest.fail("golden traces need opspec.testing.golden, which this installation "
                    "lacks", pytrace=False)
    regenerate = bool(request.config.getoption("--opspec-regen-golden"))
    near = request.node.path

    def check(run: Any, path: str | Path, **options: Any) -> Any:
        __tracebackhide__ = True
        target = Path(path) if Path(path).is_absolute() else near.parent / path
        return golden_module.compare_golden(run, target, regenerate=regenerate, **options)

    return check


@pytest.fixture
def device_url(request: pytest.FixtureRequest) -> str:
    """``--device-url``; the test is skipped when it is not given."""
    url = request.config.getoption("--device-url")
    if not url:
        pytest.skip("needs a real device: run pytest with --device-url=/dev/ttyUSB0 (or a "
                    "pySerial URL) and -m hardware")
    return str(url)


@pytest.fixture
def device_profile(request: pytest.FixtureRequest) -> str:
    """``--device-profile`` (default ``medication_dispenser``)."""
    return str(request.config.getoption("--device-profile"))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]
                              ) -> Generator[None, Any, None]:
    outcome = yield
    report: pytest.TestReport = outcome.get_result()
    if call.excinfo is not None and isinstance(call.excinfo.value, OpspecError) and (
            report.failed and not isinstance(item, ScenarioItem)):
        # an opspec error in a test is a usage problem: its message says what and how to
        # fix it; the test line that caused it is enough context (no opspec internals)
        report.longrepr = _opspec_error_repr(item, call.excinfo)
    seed = item.stash.get(_SEED_KEY, None)
    lines = []
    if seed is not None and report.failed:
        base = item.config.getoption("--opspec-seed")
        # the id is relative to the rootdir, which without a pytest configuration file
        # follows the folder pytest runs in: say which, or a rerun from elsewhere differs
        lines.append(f"seed {seed} (from --opspec-seed={base} and the test id "
                     f"{item.nodeid!r}, relative to the rootdir {item.config.rootpath}; "
                     "simulate(seed=...) overrides it)")
    if report.when == "call":
        lines.extend(item.stash.get(_WARNED_KEY, {}))
        lines.extend(f"note: {line}" for line in item.stash.get(_NOTED_KEY, {}))
    if lines:
        report.sections.append(("opspec", "\n".join(lines)))


def pytest_sessionfinish(session: pytest.Session) -> None:
    """On a pytest-xdist worker: hand the warnings it saw to the controller, which prints the
    session's (its terminal summary is the only one shown; with ``-n 2`` they were lost)."""
    output = getattr(session.config, "workeroutput", None)
    if output is not None:
        output["opspec_warned"] = list(session.config.stash.get(_WARNED_KEY, {}))
        output["opspec_noted"] = list(session.config.stash.get(_NOTED_KEY, {}))


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """On the pytest-xdist controller: a worker's warnings join the session's."""
    output = getattr(node, "workeroutput", {})
    for key, name in ((_WARNED_KEY, "opspec_warned"), (_NOTED_KEY, "opspec_noted")):
        kept = node.config.stash.setdefault(key, {})
        for line in output.get(name, ()):
            kept[line] = None


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """The warnings on every spec simulated in the session, once each, at the end (where
    pytest lists its own warnings): a spec's doubtful construct is not lost in a green run."""
    warned = terminalreporter.config.stash.get(_WARNED_KEY, {})
    if warned:
        terminalreporter.write_sep("=", "opspec: warnings on the specs simulated")
        for line in warned:
            terminalreporter.write_line(line)
    noted = terminalreporter.config.stash.get(_NOTED_KEY, {})
    if noted:
        terminalreporter.write_sep("=", "opspec: claims that held on replications all alike")
        for line in noted:
            terminalreporter.write_line(line)


def _opspec_error_repr(item: pytest.Item, excinfo: pytest.ExceptionInfo[BaseException]
                       ) -> str:
    error = excinfo.value
    where = ""
    for entry in reversed(excinfo.traceback):
        if Path(str(entry.path)) == item.path:
            line = entry.statement.lines[0].strip() if entry.statement.lines else ""
            where = f"{item.path.name}:{entry.lineno + 1}: {line}\n"
            break
    return f"{where}{type(error).__name__}: {error}"


# ---------------------------------------------------------------- scenario files
def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> pytest.Collector | None:
    if file_path.name.endswith(".scenario.toml"):
        collector: pytest.Collector = ScenarioFile.from_parent(parent, path=file_path)
        return collector
    return None


class ScenarioFile(pytest.File):
    """A ``*.scenario.toml`` file: one test item per ``[[scenario]]``."""

    def collect(self) -> Sequence[pytest.Item]:
        from opspec.testing.scenario import load_scenarios

        try:
            document = load_scenarios(self.path, rootdir=self.config.rootpath)
        except OpspecError as error:
            raise self.CollectError(f"bad scenario file: {error}") from None
        return [ScenarioItem.from_parent(self, name=scenario.name, scenario=scenario)
                for scenario in document.scenarios]


class ScenarioFailure(Exception):
    """A scenario whose expectations did not hold (the message says which and why)."""


class ScenarioItem(pytest.Item):
    """One scenario: run its ``given``, check each ``then``."""

    def __init__(self, *, scenario: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.scenario = scenario

    def runtest(self) -> None:
        from opspec.testing.scenario import run_scenario
        from opspec.testing.simulation import derive_seed

        seed = derive_seed(self.config.getoption("--opspec-seed"), self.nodeid)
        if self.scenario.seed is None:
            self.stash[_SEED_KEY] = seed
        package = load_cached(self.scenario.spec_path, self.config)[1]
        try:
            failures = run_scenario(self.scenario, package, seed=seed,
                                    seen=lambda result: _warned(self, self.config, result),
                                    noted=lambda line: _noted(self, self.config, line))
        except OpspecError as error:
            raise ScenarioFailure(f"{self.scenario.place()}: {error}") from None
        if failures:
            raise ScenarioFailure("\n\n".join(failures))

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str:
        if isinstance(excinfo.value, ScenarioFailure):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo, style=style))

    def reportinfo(self) -> tuple[Path, int | None, str]:
        # the line its [[scenario]] is written on (pytest's lines count from 0): a test
        # report's header, --verbose and an editor's jump land on the scenario
        line = self.scenario.line()
        return self.path, None if line is None else line - 1, f"scenario: {self.name}"
