"""The XPDL front end: hardened reading, normalising, model building and cross-file resolution.

Public API::

    load_package(path, *, strict=False, max_bytes=...) -> LoadResult   # never raises for bad input
    load_spec(path, *, strict=False, max_bytes=...) -> Package         # raises SpecError
    parse_bytes(data, *, path=..., strict=False, max_bytes=...) -> LoadResult
    read_xml(data, *, path, max_bytes=...) -> (lxml root, XpdlVersion) # raises XmlReadError
"""

from opspec.xpdl.loader import LoadResult, load_package, load_spec, parse_bytes
from opspec.xpdl.reader import DEFAULT_MAX_BYTES, XmlReadError, read_xml

__all__ = [
    "DEFAULT_MAX_BYTES",
    "LoadResult",
    "XmlReadError",
    "load_package",
    "load_spec",
    "parse_bytes",
    "read_xml",
]
