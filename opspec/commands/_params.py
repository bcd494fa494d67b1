"""``--param`` and ``--params FILE``: values for a spec's package data fields — a BPMN
diagram's run inputs (variables its conditions read that nothing in it sets: the application
would set them; docs/bpmn.md, Run inputs) and any package-wide data field of an XPDL spec —
for one run or evaluation.

- ``--param NAME=VALUE``: the same value in every run, read as the field's declared type;
- ``--param NAME~DISTRIBUTION``: a value drawn per run (per simulated user of ``evaluate``)
  from a distribution written as an ``opspec:Duration`` is (``uniform(0, 100)``,
  ``normal(mean=60, sd=10)``, ``lognormal(median=60, sigma=0.5)``: the spec's vocabulary,
  read by its reader);
- ``--params FILE``: a ``.toml`` or ``.json`` file of ``NAME = value`` or ``NAME = { kind =
  "normal", mean = 60, sd = 10 }`` (a user model's distribution tables), or a ``.csv`` file
  (or a JSON list of objects) with one row per run: run ``r`` (simulated user ``r`` of
  ``evaluate``) gets row ``r``.

``--param`` wins over the file for the same name. A distribution's normal is not truncated at
0 as a duration's is (a run input may be negative) unless it gives ``min``/``max``.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError, OpspecError
from opspec.model import Package
from opspec.model.data import BasicKind, BasicType, DataField
from opspec.run_inputs import RunInputs, no_such_field

__all__ = ["read_run_inputs"]

_TRUE = {"true", "yes", "1", "on"}
_FALSE = {"false", "no", "0", "off"}
_NUMBERS = (BasicKind.INTEGER, BasicKind.FLOAT)
_SUFFIXES = (".toml", ".json", ".csv")


def read_run_inputs(texts: Iterable[str], file: str | None, package: Package) -> RunInputs:
    """The ``--param`` texts and the ``--params`` file (or None) as :class:`RunInputs` of
    ``package``'s package-wide data fields: typed, every distribution checked."""
    fields = {f.id: f for f in package.data_fields}
    values: dict[str, Any] = {}
    draws: dict[str, tuple[Mapping[str, Any], bool]] = {}
    rows: tuple[Mapping[str, Any], ...] = ()
    if file is not None:
        rows = _read_file(file, fields, package, values, draws)
    for text in texts:
        name, sep, raw = _split(text)
        field = _field(name, fields, package, "--param")
        values.pop(name, None)
        draws.pop(name, None)
        if sep == "=":
            values[name] = _typed(name, raw.strip(), field.type, f"--param {name}={raw}")
        else:
            draws[name] = _drawn_from_text(name, raw, field, f"--param {text}")
    given = set(values) | set(draws)
    rows = tuple({k: v for k, v in row.items() if k not in given} for row in rows)
    return RunInputs(values=tuple(values.items()),
                     draws=tuple((n, t, i) for n, (t, i) in draws.items()),
                     rows=rows if any(rows) else (), source=file or "")


def _split(text: str) -> tuple[str, str, str]:
    cut = min((i for i in (text.find("="), text.find("~")) if i >= 0), default=-1)
    name = text[:cut].strip() if cut > 0 else ""
    if not name:
        raise ConfigurationError(f"--param {text!r} is not NAME=VALUE or NAME~DISTRIBUTION",
                                 hint="for example --param score=70 or --param "
                                 "'score~uniform(0, 100)'")
    return name, text[cut], text[cut + 1:]


def _field(name: str, fields: Mapping[str, DataField], package: Package, where: str
           ) -> DataField:
    field = fields.get(name)
    if field is None:
        raise no_such_field(name, package, where)
    return field


def _kind(field: DataField) -> BasicKind:
    return field.type.kind if isinstance(field.type, BasicType) else BasicKind.STRING


def _typed(name: str, raw: str, data_type: object, where: str) -> Any:
    kind = data_type.kind if isinstance(data_type, BasicType) else BasicKind.STRING
    try:
        if kind is BasicKind.INTEGER:
            return int(raw)
        if kind is BasicKind.FLOAT:
            value = float(raw)
            if not math.isfinite(value):
                raise ValueError(raw)
            return value
    except ValueError:
        what = "an integer" if kind is BasicKind.INTEGER else "a number"
        raise ConfigurationError(f"{where}: {name} is {what}, and {raw!r} is not one",
                                 hint=f"for example {name}=70") from None
    if kind is BasicKind.BOOLEAN:
        if raw.lower() in _TRUE:
            return True
        if raw.lower() in _FALSE:
            return False
        raise ConfigurationError(f"{where}: {name} is a boolean, and {raw!r} is not one",
                                 hint=f"write {name}=true or {name}=false")
    return raw


def _numeric(name: str, field: DataField, where: str) -> bool:
    """Whether ``field`` takes drawn values rounded (an integer); refuses other types."""
    kind = _kind(field)
    if kind not in _NUMBERS:
        raise ConfigurationError(
            f"{where}: {name} is a {kind.value.lower()}, and only a number is drawn from a "
            "distribution", hint="give it a value, or decide the choice it makes by branch "
            "probabilities (opspec:Probability on the flows: docs/bpmn.md, Undecided gateways)")
    return kind is BasicKind.INTEGER


def _drawn_from_text(name: str, text: str, field: DataField, where: str
                     ) -> tuple[Mapping[str, Any], bool]:
    from opspec.distributions.factory import from_model
    from opspec.xpdl.sisarl_values import parse_distribution

    integer = _numeric(name, field, where)
    try:
        declared = parse_distribution(text)
    except OpspecError as error:
        raise ConfigurationError(f"{where}: {error.message}", hint=error.hint) from None
    given = {k for k, _v in declared.parameters}
    if "normal" in declared.kind.lower() and not given & {"min", "low"}:
        declared = type(declared)(kind=declared.kind,
                                  parameters=(*declared.parameters, ("min", -math.inf)))
    try:
        return from_model(declared).to_params(), integer
    except OpspecError as error:
        raise ConfigurationError(f"{where}: {error.message}", hint=error.hint) from None


def _drawn_from_table(name: str, table: Mapping[str, Any], field: DataField, where: str
                      ) -> tuple[Mapping[str, Any], bool]:
    from opspec.distributions import make_distribution

    integer = _numeric(name, field, where)
    table = dict(table)
    if str(table.get("kind", "")).lower() in ("normal", "normaldistribution") and not (
            {"low", "min"} & set(table)):
        table["low"] = -math.inf
    try:
        return make_distribution(table).to_params(), integer
    except OpspecError as error:
        raise ConfigurationError(f"{where}: {error.message}", hint=error.hint) from None


def _read_file(file: str, fields: Mapping[str, DataField], package: Package,
               values: dict[str, Any], draws: dict[str, tuple[Mapping[str, Any], bool]]
               ) -> tuple[Mapping[str, Any], ...]:
    """Fills ``values`` and ``draws`` from a TOML/JSON mapping; returns a CSV's (or JSON
    list's) rows."""
    from opspec.files import json_loads, json_problem, read_bytes, reason

    suffix = Path(file).suffix.lower()
    if suffix not in _SUFFIXES:
        raise ConfigurationError(f"--params {file}: opspec reads .toml, .json or .csv files",
                                 hint="name the file NAME.toml (NAME = value), NAME.json or "
                                 "NAME.csv (a header of names, one row per run)")
    try:
        raw = read_bytes(file)
    except OSError as error:
        raise ConfigurationError(f"--params {file}: cannot read it: {reason(error)}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise ConfigurationError(f"--params {file}: not UTF-8 text (byte "
                                 f"0x{error.object[error.start]:02x} at offset {error.start})",
                                 hint="save the file as UTF-8") from None
    if suffix == ".csv":
        return _csv_rows(file, text, fields, package)
    if suffix == ".toml":
        from opspec.toml_files import parse_toml

        doc: Any = parse_toml(text, where=file, what="the --params file")
    else:
        import json

        try:
            doc = json_loads(text)
        except json.JSONDecodeError as error:
            raise ConfigurationError(f"{file}:{error.lineno}: not valid JSON: "
                                     f"{json_problem(error)}") from None
    if isinstance(doc, list):
        return tuple(_row(file, f"row {i + 1}", item, fields, package)
                     for i, item in enumerate(doc))
    if not isinstance(doc, Mapping):
        raise ConfigurationError(f"--params {file}: expected NAME = value entries",
                                 hint="for example score = 70, or score = { kind = "
                                 "\"uniform\", low = 0, high = 100 }")
    for name, value in doc.items():
        field = _field(name, fields, package, f"{file}")
        where = f"{file}: {name}"
        if isinstance(value, Mapping):
            draws[name] = _drawn_from_table(name, value, field, where)
        else:
            values[name] = _from_file(name, value, field, where)
    return ()


def _from_file(name: str, value: Any, field: DataField, where: str) -> Any:
    """A TOML/JSON value as the field's type (text is read as on the command line)."""
    if isinstance(value, str):
        return _typed(name, value.strip(), field.type, where)
    if isinstance(value, (list, Mapping)) or value is None:
        raise ConfigurationError(f"{where}: a value or a distribution table is expected, "
                                 f"not {value!r}",
                                 hint=f'{name} = 70 or {name} = {{ kind = "uniform", low = 0, '
                                 "high = 100 }")
    return _typed(name, str(value).lower() if isinstance(value, bool) else str(value),
                  field.type, where)


def _row(file: str, where: str, item: Any, fields: Mapping[str, DataField],
         package: Package) -> Mapping[str, Any]:
    if not isinstance(item, Mapping):
        raise ConfigurationError(f"--params {file}: {where} is not an object of NAME: value")
    return {name: _from_file(name, value, _field(name, fields, package, f"{file}"),
                             f"{file}: {where}: {name}") for name, value in item.items()}


def _csv_rows(file: str, text: str, fields: Mapping[str, DataField], package: Package
              ) -> tuple[Mapping[str, Any], ...]:
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        header = [h.strip() for h in next(reader)]
    except StopIteration:
        raise ConfigurationError(f"{file}: the file is empty",
                                 hint="a header of run-input names, then one row per run"
                                 ) from None
    except csv.Error as error:
        raise ConfigurationError(f"{file}:1: not CSV: {error}") from None
    for name in header:
        _field(name, fields, package, f"{file}:1")
    rows: list[Mapping[str, Any]] = []
    try:
        for cells in reader:
            line = reader.line_num
            if not any(c.strip() for c in cells):
                continue                              # blank lines, as spreadsheets leave
            if len(cells) != len(header):
                raise ConfigurationError(f"{file}:{line}: {len(cells)} values for "
                                         f"{len(header)} names", hint="one value per column "
                                         "of the header")
            row: dict[str, Any] = {}
            for name, cell in zip(header, cells, strict=True):
                if not cell.strip():
                    raise ConfigurationError(f"{file}:{line}: no value for {name}",
                                             hint="every row gives every column a value")
                row[name] = _typed(name, cell.strip(), fields[name].type, f"{file}:{line}")
            rows.append(row)
    except csv.Error as error:
        raise ConfigurationError(f"{file}:{reader.line_num}: not CSV: {error}") from None
    if not rows:
        raise ConfigurationError(f"{file}: the file has a header and no rows",
                                 hint="one row per run (per simulated user of evaluate)")
    return tuple(rows)
