"""The engine compiled with mypyc (setup.py, opspec/_native.py) and run from source agree, and
a compiled build whose source changed is never the one that runs."""

from __future__ import annotations

import importlib.machinery
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from opspec import _native

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
MODEL = ROOT / "specs" / "medication_dispenser.users.toml"

_PROBE = ("import json, opspec, opspec._native as n, opspec.engine.interpreter as i;"
          "print(json.dumps([n.COMPILED, n.STATUS, i.__file__]))")


def _python(code: str, pure: bool) -> str:
    env = {k: v for k, v in os.environ.items() if k != _native.ENV}
    if pure:
        env[_native.ENV] = "1"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=ROOT, check=True)
    return done.stdout


def _run_json(pure: bool) -> dict[str, object]:
    code = ("import sys; from opspec.cli import main; sys.argv = ['opspec', 'run', "
            f"{str(SPEC)!r}, '--days', '4', '--seed', '7', '--user-model', {str(MODEL)!r}, "
            "'--json']; main()")
    result = json.loads(_python(code, pure))
    assert isinstance(result, dict)
    return result


def test_opspec_pure_python_runs_every_module_from_its_source() -> None:
    compiled, status, interpreter = json.loads(_python(_PROBE, pure=True))
    assert not compiled and "OPSPEC_PURE_PYTHON is set" in status
    assert interpreter.endswith("interpreter.py")


def test_the_build_runs_compiled_when_it_is_fresh() -> None:
    compiled, status, interpreter = json.loads(_python(_PROBE, pure=False))
    if not compiled and "changed since it was compiled" in status \
            and os.environ.get("OPSPEC_REQUIRE_COMPILED") != "1":
        pytest.skip(f"engine source edited since the build: {status}")
    if not any(_native._has_extension(m) for m in _native.MODULES):
        # scripts/test.sh (what CI runs) has just installed with a C compiler at hand, so there
        # a pure-Python install means the compile failed silently behind pip --quiet.
        if os.environ.get("OPSPEC_REQUIRE_COMPILED") == "1":
            pytest.fail(f"the engine should have been compiled at install: {status}; "
                        f"run `pip install -v -e .` to see why it was not")
        pytest.skip(f"this installation was not compiled: {status}")
    assert compiled, status
    assert not interpreter.endswith(".py")


def test_compiled_and_source_engines_give_the_same_run() -> None:
    pure, default = _run_json(pure=True), _run_json(pure=False)
    assert pure["metrics"] == default["metrics"]
    assert pure == default


def _fake_install(tmp_path: Path, digest_of: dict[str, str] | None) -> None:
    for module in _native.MODULES:
        source = tmp_path / (module.replace(".", "/") + ".py")
        source.parent.mkdir(parents=True, exist_ok=True)
        source.write_text(f"# {module}\n", encoding="utf-8")
        source.with_suffix(".cpython-311-x86_64-linux-gnu.so").write_bytes(b"")
    if digest_of is not None:
        modules = {m: digest_of.get(m, _native.source_digest(
            tmp_path / (m.replace(".", "/") + ".py"))) for m in _native.MODULES}
        (tmp_path / "opspec" / _native.STAMP).write_text(
            json.dumps({"compiler": "mypyc", "modules": modules}), encoding="utf-8")


@pytest.fixture
def fake_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setattr(_native, "_PACKAGE_ROOT", tmp_path)
    monkeypatch.setattr(_native.importlib.machinery, "EXTENSION_SUFFIXES",
                        [".cpython-311-x86_64-linux-gnu.so"])
    monkeypatch.delenv(_native.ENV, raising=False)
    return tmp_path


def test_a_fresh_build_is_used(fake_root: Path) -> None:
    _fake_install(fake_root, {})
    assert _native._decide() == (True, f"compiled with mypyc ({len(_native.MODULES)} modules)")


def test_an_edited_source_sends_every_module_back_to_its_source(fake_root: Path) -> None:
    _fake_install(fake_root, {"opspec.engine.interpreter": "0" * 64})
    compiled, why = _native._decide()
    assert not compiled
    assert "opspec.engine.interpreter changed since it was compiled" in why
    assert "pip install -e ." in why


def test_a_build_without_its_record_is_not_trusted(fake_root: Path) -> None:
    _fake_install(fake_root, None)
    compiled, why = _native._decide()
    assert not compiled and "reinstall to compile" in why


def test_the_finder_loads_source_only_for_the_modules_it_routes() -> None:
    finder = _native._FromSource(frozenset(_native.MODULES))
    spec = finder.find_spec("opspec.engine.interpreter")
    assert spec is not None and spec.origin is not None
    assert spec.origin.endswith("opspec/engine/interpreter.py")
    assert finder.find_spec("opspec.engine.trace") is None


def test_a_module_no_longer_compiled_runs_from_source_though_its_old_build_remains(
        fake_root: Path) -> None:
    """A module taken out of MODULES (opspec.engine.clock was, when its Clock came to subclass
    simpy.Environment) keeps its extension file in an editable checkout until it is rebuilt;
    Python prefers an extension to the source beside it, so without routing, the stale build
    would run instead of the code (an ImportError for any name added since)."""
    _fake_install(fake_root, {})
    stamp = fake_root / "opspec" / _native.STAMP
    record = json.loads(stamp.read_text(encoding="utf-8"))
    record["modules"]["opspec.engine.old_module"] = "0" * 64
    stamp.write_text(json.dumps(record), encoding="utf-8")
    old = fake_root / "opspec" / "engine" / "old_module.py"
    old.write_text("# now pure Python\n", encoding="utf-8")
    old.with_suffix(".cpython-311-x86_64-linux-gnu.so").write_bytes(b"")
    assert _native._left_compiled() == {"opspec.engine.old_module"}
    assert _native._decide()[0]           # the modules still listed run compiled


def test_a_work_item_reads_by_field_and_compares_by_value() -> None:
    from opspec.engine.performers import WorkItem

    item = WorkItem(1, "notify", 7, "press_report", "Press report", "user", "user", 60.0,
                    choices=["a", "b"])
    assert (item.activity, item.choices, item.root_instance, dict(item.data)) == (
        "press_report", ("a", "b"), None, {})
    assert item == WorkItem(1, "notify", 7, "press_report", "Press report", "user", "user",
                            60.0, choices=("a", "b"))
    assert item != WorkItem(2, "notify", 7, "press_report", "Press report", "user", "user",
                            60.0, choices=("a", "b"))
    assert repr(item).startswith("WorkItem(key=1, process='notify', instance=7,")
    if _native.COMPILED:
        with pytest.raises(AttributeError):
            item.key = 2  # type: ignore[misc]


def test_an_in_place_build_removes_only_the_extensions_no_longer_listed(tmp_path: Path) -> None:
    """setup.py deletes an earlier build's extensions of modules taken out of MODULES before
    an in-place build. The platform's suffix ('.cpython-311-x86_64-linux-gnu.so') ends in the
    bare '.so' too, so a listed module's file must be read with its longest suffix, or every
    compiled module would look unlisted and the build would delete them all."""
    platform = importlib.machinery.EXTENSION_SUFFIXES[0]
    engine = tmp_path / "opspec" / "engine"
    engine.mkdir(parents=True)
    listed = [tmp_path / (m.replace(".", "/") + platform) for m in _native.MODULES]
    stale = [engine / f"old_module{platform}", engine / "older.so"]
    for path in [*listed, *stale, engine / "flow.py"]:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(b"")
    assert _native.unlisted_extensions(tmp_path) == sorted(stale)


def test_the_build_record_describes_the_sources_mypyc_compiled(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A source edited while the C compiler runs (minutes, on one core) must not be recorded
    as compiled: the record holds the digests of what mypyc read, so opspec._native finds the
    edited module stale and runs it from its source instead of the older compiled code."""
    import runpy
    import shutil
    import types

    import setuptools
    from setuptools import Extension

    shutil.copy(ROOT / "setup.py", tmp_path / "setup.py")
    for module in (*_native.MODULES, "opspec._native"):
        relative = module.replace(".", "/") + ".py"
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / relative, tmp_path / relative)
    # mypyc as the build sees it, without compiling anything (the test venv need not have it)
    mypyc = types.ModuleType("mypyc")
    build_module = types.ModuleType("mypyc.build")
    build_module.mypycify = lambda paths, **options: [  # type: ignore[attr-defined]
        Extension("opspec__mypyc", ["build/__native_opspec.c"])]
    monkeypatch.setitem(sys.modules, "mypyc", mypyc)
    monkeypatch.setitem(sys.modules, "mypyc.build", build_module)
    monkeypatch.setattr(setuptools, "setup", lambda **options: None)
    monkeypatch.setattr(sys, "argv", ["setup.py", "build_ext", "--inplace"])
    monkeypatch.delenv(_native.ENV, raising=False)
    setup = runpy.run_path(str(tmp_path / "setup.py"))
    edited = tmp_path / (_native.MODULES[0].replace(".", "/") + ".py")
    before = _native.source_digest(edited)
    edited.write_text(edited.read_text(encoding="utf-8") + "\n# edited during the build\n",
                      encoding="utf-8")
    build = types.SimpleNamespace(inplace=True, build_lib=str(tmp_path / "build"))
    setup["OptionalNativeBuild"]._stamp(build)
    record = json.loads((tmp_path / "opspec" / _native.STAMP).read_text(encoding="utf-8"))
    assert record["modules"][_native.MODULES[0]] == before != _native.source_digest(edited)


def test_a_build_mypyc_refused_leaves_no_record_to_vouch_for_an_older_build(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """mypyc refuses the source (a type error a change brought in): the build compiles
    nothing and says so. It wrote the record of this source all the same, over the extensions
    an earlier in-place build had left, and opspec._native ran that older code as this
    source's compiled build. Now no record is left: the source runs."""
    import runpy
    import shutil
    import types

    import setuptools
    from setuptools import Distribution

    shutil.copy(ROOT / "setup.py", tmp_path / "setup.py")
    for module in (*_native.MODULES, "opspec._native"):
        relative = module.replace(".", "/") + ".py"
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / relative, tmp_path / relative)
    stamp = tmp_path / "opspec" / _native.STAMP
    stamp.write_text('{"compiler": "mypyc", "modules": {}}\n', encoding="utf-8")  # the old one

    def refuse(paths: object, **options: object) -> list[object]:
        raise SystemExit("opspec/engine/flow.py:1: error: Incompatible types")

    mypyc = types.ModuleType("mypyc")
    build_module = types.ModuleType("mypyc.build")
    build_module.mypycify = refuse  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "mypyc", mypyc)
    monkeypatch.setitem(sys.modules, "mypyc.build", build_module)
    monkeypatch.setattr(setuptools, "setup", lambda **options: None)
    monkeypatch.setattr(sys, "argv", ["setup.py", "build_ext", "--inplace"])
    monkeypatch.delenv(_native.ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    setup = runpy.run_path(str(tmp_path / "setup.py"))
    extensions = setup["_extensions"]()
    assert extensions == [] and setup["_READ"] == {}
    build = setup["OptionalNativeBuild"](Distribution({"ext_modules": extensions}))
    build.ensure_finalized()
    build.inplace = True
    build.run()
    assert not stamp.exists()
