"""The compiled workflow script (``.wfs``): a versioned JSON form of the model.

The engine loads these files at initialisation instead of parsing XPDL (devices carry scripts,
not the tools). The format is documented in ``docs/wfs-format.md``; in short::

    {"format": "opspec-wfs", "version": 1, "opspec": "0.1.0", "source": "specs/x.xpdl",
     "package": {"$": "Package", "id": "x", ...}}

Every model object is a JSON object whose ``"$"`` key is its *type tag*, taken from the explicit
:data:`TAGS` table (the file never names a Python class: a tag that is not in the table is a
corrupt file, never an import). Fields equal to their default are left out; enums are written
by value; tuples are lists. Decoders are built once per class from the dataclass type hints, so
loading is a tight loop of dict lookups and constructor calls.

Contract: ``load(dump(p)) == p`` for every model value ``p`` (expression trees, source locations
and extended attributes included). Floats that are not finite are written as the non-standard
JSON tokens ``Infinity``/``NaN`` that Python's ``json`` reads back.

Versioning: :data:`VERSION` is the version this module writes. Older documents are upgraded by
:data:`MIGRATIONS` (``{n: upgrade from n to n + 1}``) before decoding; newer ones are refused
with a message telling the user to upgrade opspec or recompile.

This module lives in ``opspec.model`` because the engine needs it; it must not import lxml.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import os
import tempfile
import types
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from opspec import __version__
from opspec.errors import SourceLocation, SpecError
from opspec.model import activities, common, data, expressions, package, process, resources, sisarl
from opspec.model.package import Package

__all__ = [
    "FORMAT",
    "MIGRATIONS",
    "TAGS",
    "VERSION",
    "dump",
    "dumps",
    "load",
    "loads",
    "read_wfs",
    "write_atomically",
    "write_wfs",
]

FORMAT = "opspec-wfs"
VERSION = 1

# The type tags of format version 1. A tag, once written to files, must keep meaning the same
# class: rename a class freely, but never reuse or change a tag without a new format version.
TAGS: Mapping[str, type] = {
    # errors / common
    "SourceLocation": SourceLocation,
    "ExtendedAttribute": common.ExtendedAttribute,
    # expressions
    "Literal": expressions.Literal,
    "Name": expressions.Name,
    "Unary": expressions.Unary,
    "Binary": expressions.Binary,
    "Call": expressions.Call,
    # data
    "BasicType": data.BasicType,
    "DeclaredType": data.DeclaredType,
    "SchemaType": data.SchemaType,
    "ExternalReferenceType": data.ExternalReferenceType,
    "RecordMember": data.RecordMember,
    "RecordType": data.RecordType,
    "UnionType": data.UnionType,
    "EnumerationType": data.EnumerationType,
    "ArrayType": data.ArrayType,
    "ListType": data.ListType,
    "TypeDeclaration": data.TypeDeclaration,
    "DataField": data.DataField,
    "FormalParameter": data.FormalParameter,
    "ActualParameter": data.ActualParameter,
    "Assignment": data.Assignment,
    # SISARL
    "Distribution": sisarl.DeclaredDistribution,
    "TriggerRef": sisarl.TriggerRef,
    "ProcessDirectives": sisarl.ProcessDirectives,
    "ActivityDirectives": sisarl.ActivityDirectives,
    "CoordinationBuiltIn": sisarl.CoordinationBuiltIn,
    "WorkflowMode": sisarl.WorkflowMode,
    "EventSelector": sisarl.EventSelector,
    "MetricDefinition": sisarl.MetricDefinition,
    # activities
    "Trigger": activities.Trigger,
    "NoImplementation": activities.NoImplementation,
    "TaskApplication": activities.TaskApplication,
    "Task": activities.Task,
    "SubFlow": activities.SubFlow,
    "Reference": activities.Reference,
    "Route": activities.Route,
    "BlockActivity": activities.BlockActivity,
    "Event": activities.Event,
    "Deadline": activities.Deadline,
    "Loop": activities.Loop,
    "Join": activities.Join,
    "Split": activities.Split,
    "Activity": activities.Activity,
    # resources
    "Participant": resources.Participant,
    "Application": resources.Application,
    "Lane": resources.Lane,
    "Pool": resources.Pool,
    # processes
    "Condition": process.Condition,
    "Transition": process.Transition,
    "ActivitySet": process.ActivitySet,
    "ProcessHeader": process.ProcessHeader,
    "WorkflowProcess": process.WorkflowProcess,
    # package
    "PackageHeader": package.PackageHeader,
    "ExternalPackage": package.ExternalPackage,
    "Package": package.Package,
}

Document = dict[str, Any]

# Upgrades of older documents: MIGRATIONS[n] turns a version-n document (the whole top-level
# object) into a version n+1 one. Version 1 is the first format, so the table is empty; the
# mechanism is exercised by the tests.
MIGRATIONS: dict[int, Callable[[Document], Document]] = {}

_TAG_OF: dict[type, str] = {cls: tag for tag, cls in TAGS.items()}
_MISSING = dataclasses.MISSING
_SCALARS = (str, int, float, bool, type(None))


class _CorruptError(Exception):
    """Internal: the document does not describe a model; turned into a SpecError by callers.
    ``where``: the objects and field it was found in, outermost first (a hand-edited script's
    "expected str, got 5" alone does not say which of its thousands of values it is)."""

    def __init__(self, message: str, where: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.message = message
        self.where = where

    def __str__(self) -> str:
        if not self.where:
            return self.message
        *objects, field = self.where
        return f"{self.message} (in {' > '.join(objects)}, field {field})"


# --------------------------------------------------------------------------- encoding


def _field_defaults(cls: type) -> tuple[tuple[str, Any], ...]:
    out = []
    for f in dataclasses.fields(cls):
        if f.default is not _MISSING:
            default: Any = f.default
        elif f.default_factory is not _MISSING:
            default = f.default_factory()
        else:
            default = _MISSING
        out.append((f.name, default))
    return tuple(out)


_DEFAULTS: dict[type, tuple[tuple[str, Any], ...]] = {cls: _field_defaults(cls) for cls in TAGS.values()}


def _encode(value: Any) -> Any:
    if value is None or isinstance(value, (str, bool, int, float)):
        return value
    if isinstance(value, tuple):
        return [_encode(item) for item in value]
    if isinstance(value, enum.Enum):
        return value.value
    cls = type(value)
    tag = _TAG_OF.get(cls)
    if tag is None:
        raise TypeError(
            f"cannot write a {cls.__qualname__} to a .wfs: it has no type tag "
            "(add it to opspec.model.codec.TAGS)"
        )
    out: dict[str, Any] = {"$": tag}
    for name, default in _DEFAULTS[cls]:
        item = getattr(value, name)
        if default is not _MISSING and (item is default or item == default):
            continue
        out[name] = _encode(item)
    return out


def dump(package: Package) -> Document:
    """The ``.wfs`` document (a JSON-ready dict) of ``package``."""
    return {
        "format": FORMAT,
        "version": VERSION,
        "opspec": __version__,
        "source": package.source,
        "package": _encode(package),
    }


def dumps(package: Package) -> str:
    """``dump`` as JSON text (compact, deterministic, ASCII)."""
    return json.dumps(dump(package), separators=(",", ":"))


# --------------------------------------------------------------------------- decoding

Decoder = Callable[[Any], Any]


def _identity(value: Any) -> Any:
    return value


def _check_scalar(kinds: tuple[type, ...]) -> Decoder:
    # bool is an int in Python; JSON keeps them apart, and so must we for `int` fields.
    def decode(value: Any) -> Any:
        if type(value) in kinds:
            return value
        raise _CorruptError(f"expected {'/'.join(k.__name__ for k in kinds)}, got {value!r}")

    return decode


def _enum_decoder(cls: type[enum.Enum]) -> Decoder:
    members = {member.value: member for member in cls}

    def decode(value: Any) -> Any:
        try:
            return members[value]
        except (KeyError, TypeError):
            raise _CorruptError(f"{value!r} is not a {cls.__name__}") from None

    return decode


def _object_decoder(expected: tuple[type, ...]) -> Decoder:
    def decode(value: Any) -> Any:
        if type(value) is not dict:
            raise _CorruptError(f"expected an object, got {value!r}")
        cls = TAGS.get(value.get("$"))  # type: ignore[arg-type]
        if cls is None:
            raise _CorruptError(f"unknown type tag {value.get('$')!r}")
        if not issubclass(cls, expected):
            raise _CorruptError(f"a {value['$']} cannot stand here")
        return _decode_object(cls, value)

    return decode


def _tuple_decoder(item: Decoder) -> Decoder:
    if item is _identity:
        def decode_plain(value: Any) -> Any:
            if type(value) is not list:
                raise _CorruptError(f"expected a list, got {value!r}")
            return tuple(value)

        return decode_plain

    def decode(value: Any) -> Any:
        if type(value) is not list:
            raise _CorruptError(f"expected a list, got {value!r}")
        return tuple([item(v) for v in value])

    return decode


def _fixed_tuple_decoder(items: tuple[Decoder, ...]) -> Decoder:
    def decode(value: Any) -> Any:
        if type(value) is not list or len(value) != len(items):
            raise _CorruptError(f"expected a list of {len(items)}, got {value!r}")
        return tuple([dec(v) for dec, v in zip(items, value)])

    return decode


def _decoder_for(hint: Any) -> Decoder:
    """A decoder for values annotated ``hint`` (built once per field)."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        optional = type(None) in args
        rest = tuple(a for a in args if a is not type(None))
        if all(a in _SCALARS for a in rest):
            kinds = rest + ((type(None),) if optional else ())
            if float in kinds:  # JSON writes 1.0 as 1.0, but accept an int for a float field
                kinds = kinds + (int,)
            return _check_scalar(kinds)
        if len(rest) == 1:
            inner = _decoder_for(rest[0])
        else:
            inner = _object_decoder(rest)
        if not optional:
            return inner

        def decode_optional(value: Any) -> Any:
            return None if value is None else inner(value)

        return decode_optional
    if origin is tuple:
        args = typing.get_args(hint)
        if len(args) == 2 and args[1] is Ellipsis:
            return _tuple_decoder(_decoder_for(args[0]))
        return _fixed_tuple_decoder(tuple(_decoder_for(a) for a in args))
    if isinstance(hint, type):
        if issubclass(hint, enum.Enum):
            return _enum_decoder(hint)
        if dataclasses.is_dataclass(hint):
            return _object_decoder((hint,))
        if hint is float:
            return _check_scalar((float, int))
        if hint in _SCALARS:
            return _check_scalar((hint,))
    raise TypeError(f"opspec.model.codec cannot decode fields annotated {hint!r}")


_FIELD_DECODERS: dict[type, dict[str, Decoder]] = {}


def _build_decoders() -> None:
    # Resolve each class's annotations in its own module (no shared namespace: two modules
    # both define a ``Mode``, and a merged namespace would take precedence over the right one).
    for cls in TAGS.values():
        hints = typing.get_type_hints(cls)
        _FIELD_DECODERS[cls] = {
            f.name: _decoder_for(hints[f.name]) for f in dataclasses.fields(cls)
        }


def _decode_object(cls: type, value: dict[str, Any]) -> Any:
    decoders = _FIELD_DECODERS[cls]
    kwargs: dict[str, Any] = {}
    for key, item in value.items():
        if key == "$":
            continue
        decoder = decoders.get(key)
        if decoder is None:
            raise _CorruptError(f"{value['$']} has no field {key!r}")
        try:
            kwargs[key] = decoder(item)
        except _CorruptError as error:
            ident = value.get("id")
            label = value["$"] + (f" {ident!r}" if type(ident) is str else "")
            raise _CorruptError(error.message, (label, *(error.where or (key,)))) from None
    try:
        return cls(**kwargs)
    except TypeError as error:  # a required field is missing
        raise _CorruptError(f"{value['$']}: {error}") from None


_build_decoders()
_decode_package = _object_decoder((Package,))


def _upgrade(document: Document) -> Document:
    version = document.get("version")
    # Version 1 is the first format; anything below it is only known through a migration.
    if type(version) is not int or (version < 1 and version not in MIGRATIONS):
        raise _CorruptError(f"unknown format version {version!r}")
    if version > VERSION:
        raise SpecError(
            f"this workflow script has format version {version}, but this opspec "
            f"({__version__}) reads versions up to {VERSION}",
            hint="upgrade opspec, or recompile the XPDL with `opspec compile`",
        )
    while version < VERSION:
        migrate = MIGRATIONS.get(version)
        if migrate is None:
            raise SpecError(
                f"format version {version} is no longer supported (no migration to "
                f"{version + 1})",
                hint="recompile the XPDL with `opspec compile`",
            )
        document = migrate(document)
        version += 1
        document["version"] = version
    return document


def load(obj: Any, *, where: str = "<.wfs document>") -> Package:
    """The package a ``.wfs`` document (as returned by :func:`dump`) describes.

    Raises :class:`SpecError` naming ``where`` when the document is not an opspec workflow
    script, has a newer format version than this opspec reads, or does not describe a model.
    """
    if type(obj) is not dict or obj.get("format") != FORMAT:
        raise SpecError(
            f"{where}: not an opspec workflow script (no \"format\": \"{FORMAT}\")",
            hint="compile an XPDL file with `opspec compile SPEC.xpdl` to get one",
        )
    try:
        document = _upgrade(dict(obj))
        result = _decode_package(document.get("package"))
    except SpecError as error:
        raise SpecError(f"{where}: {error.message}", hint=error.hint) from None
    except _CorruptError as error:
        raise SpecError(
            f"{where}: corrupt workflow script: {_short(str(error))}",
            hint="recompile the XPDL with `opspec compile`",
        ) from None
    except (RecursionError, ValueError, OverflowError) as error:
        # nested past what the decoder can follow, or a number no field can hold
        raise SpecError(
            f"{where}: corrupt workflow script: {type(error).__name__}: "
            f"{_short(str(error))}",
            hint="recompile the XPDL with `opspec compile`",
        ) from None
    package_value: Package = result
    return package_value


def _short(text: str, most: int = 200) -> str:
    """``text`` cut to ``most`` characters (a corrupt value may be megabytes long)."""
    return text if len(text) <= most else f"{text[:most]}… ({len(text):,} characters)"


#: How deeply a ``.wfs`` document may nest (the dispenser's is 13 levels; each nested block
#: activity adds a few): deeper is refused as not one of ours, before the decoder recurses.
WFS_MAX_NESTING = 200


def loads(text: str | bytes, *, where: str = "<.wfs text>") -> Package:
    """:func:`load` of JSON text; corrupt JSON is a :class:`SpecError` with its line."""
    from opspec.files import json_loads, json_problem

    try:
        # a compiled package nests a few dozen levels; far deeper is not one of ours, and
        # would only exhaust the decoder's recursion (a number past Python's limit likewise)
        obj = json_loads(text, most=WFS_MAX_NESTING)
    except json.JSONDecodeError as error:
        raise SpecError(
            f"corrupt workflow script (invalid JSON: {json_problem(error)})",
            location=SourceLocation(where, error.lineno),
            hint="recompile the XPDL with `opspec compile`",
        ) from None
    except (UnicodeDecodeError, RecursionError) as error:
        raise SpecError(
            f"{where}: not an opspec workflow script ({type(error).__name__})",
            hint="compile an XPDL file with `opspec compile SPEC.xpdl` to get one",
        ) from None
    return load(obj, where=where)


# --------------------------------------------------------------------------- files


def _file_mode(target: Path) -> int:
    """The permission bits for writing ``target``: those of the file it replaces, else
    0666 without the process's umask (as ``open()`` would create it)."""
    try:
        return target.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0o022)
        os.umask(umask)
        return 0o666 & ~umask


def write_wfs(package: Package, path: str | os.PathLike[str]) -> None:
    """Write ``package`` to ``path`` atomically (see :func:`write_atomically`), so a reader
    never sees half a script. Its ``source`` is written relative to the script's folder
    (:func:`read_wfs` turns it back into a path from the current folder). ``OSError``
    propagates (the caller reports it as an I/O problem)."""
    if package.source:
        package = dataclasses.replace(package, source=_from_folder(package.source, path))
    write_atomically(path, dumps(package).encode("ascii") + b"\n")


# A spec names its companion files (opspec:WorldFile, a mode's Source, ExternalPackage hrefs)
# relative to its own folder, found from Package.source. A source written as compile was
# given it (relative to the folder compile ran in) led nowhere from any other folder: 'opspec
# run specs/vacuum_cleaner.wfs' worked from one folder only. Relative to the script, it holds
# wherever the command runs and when the script and its spec move together (an absolute path
# is kept as given).

def _from_folder(source: str, script: str | os.PathLike[str]) -> str:
    """``source`` (a path from the current folder) as a path from ``script``'s folder; an
    absolute path stays as it is."""
    if "://" in source or os.path.isabs(source):
        return source
    try:
        moved = os.path.relpath(os.path.abspath(source),
                                os.path.dirname(os.path.abspath(script)))
    except ValueError:                  # another drive (Windows): no relative path there
        return source
    return Path(moved).as_posix()


def _from_here(source: str, script: str | os.PathLike[str]) -> str:
    """``source`` as stored in ``script`` (relative to the script's folder) as a path from
    the current folder: relative when it lies below it, else absolute. A script written before
    sources were stored that way holds a path from the folder it was compiled in: when only
    that path leads to a file, it is kept."""
    if "://" in source or os.path.isabs(source):
        return source
    found = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(script)), source))
    if not os.path.exists(found) and os.path.isfile(source):
        return source
    here = os.path.relpath(found)
    return found if here == os.pardir or here.startswith(os.pardir + os.sep) else here


def write_atomically(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename, so
    a reader sees the old file or the whole new one, never half of it. The file gets the mode
    of the file it replaces, else that of an ordinary new file. ``OSError`` propagates; the
    temporary file is removed then."""
    target = Path(path)
    handle, temp_name = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=".tmp", dir=target.parent if str(target.parent) else "."
    )
    try:
        # mkstemp creates the file 0600; give it the mode an ordinary new file would get
        # (0666 minus the umask), or keep the mode of the file it replaces.
        os.fchmod(handle, _file_mode(target))
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.replace(temp_name, target)
    except BaseException:
        try:
            os.unlink(temp_name)
        except OSError:
            pass
        raise


def read_wfs(path: str | os.PathLike[str]) -> Package:
    """The package stored in the ``.wfs`` file at ``path``, its ``source`` a path from the
    current folder (:func:`write_wfs`).

    Raises :class:`SpecError` when the file cannot be read, is not a workflow script (an XPDL
    file given by mistake, another JSON file), comes from a newer opspec, or is corrupt.
    """
    where = os.fspath(path)
    try:
        raw = Path(path).read_bytes()
    except OSError as error:
        raise SpecError(
            f"{where}: cannot read the workflow script: {error.strerror or error}",
            hint="check the path",
        ) from None
    if raw.lstrip()[:1] == b"<":
        raise SpecError(
            f"{where}: this is XML (an XPDL file?), not a compiled workflow script",
            hint=f"compile it with `opspec compile {where}`, or load it as XPDL",
        )
    package = loads(raw, where=where)
    if package.source:
        package = dataclasses.replace(package, source=_from_here(package.source, path))
    return package
