"""Reading a specification file's bytes under the size limit: :data:`DEFAULT_MAX_BYTES`,
replaced by the environment variable :data:`MAX_BYTES_VARIABLE` (:func:`effective_max_bytes`),
checked before reading a file and while reading a stream, so a 1 GB file is never read into
memory. Folders, pipes, devices and sockets are refused without blocking.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import BinaryIO, Final

from opspec.errors import SourceLocation
from opspec.files import NotARegularFile, open_regular
from opspec.xpdl.read_errors import XmlReadError

__all__ = [
    "DEFAULT_MAX_BYTES",
    "MAX_BYTES_VARIABLE",
    "effective_max_bytes",
    "read_file",
    "read_limited",
    "too_big_error",
]

#: Default size limit of one specification file (64 MiB).
DEFAULT_MAX_BYTES: Final = 64 * 1024 * 1024
#: The environment variable that sets the size limit in bytes instead of the default
#: (``OPSPEC_MAX_SPEC_BYTES=200000000 opspec validate big.xpdl``; docs/validation.md).
MAX_BYTES_VARIABLE: Final = "OPSPEC_MAX_SPEC_BYTES"
_CHUNK: Final = 1024 * 1024


def effective_max_bytes(max_bytes: int, *, path: str = "<spec>") -> int:
    """``max_bytes``, or the value of :data:`MAX_BYTES_VARIABLE` when the caller left the
    default. A value that is not a positive whole number is an :class:`XmlReadError`
    (``bad-setting``) rather than silently ignored."""
    raw = os.environ.get(MAX_BYTES_VARIABLE, "").strip()
    if max_bytes != DEFAULT_MAX_BYTES or not raw:
        return max_bytes
    try:
        value = int(raw.replace("_", ""))
    except ValueError:
        value = 0
    if value <= 0:
        raise XmlReadError(
            "bad-setting",
            f"{MAX_BYTES_VARIABLE}={raw!r} is not a positive whole number of bytes",
            location=SourceLocation(path, 1),
            hint=f"set e.g. {MAX_BYTES_VARIABLE}=200000000, or unset it for the default "
            f"of {DEFAULT_MAX_BYTES:,} bytes")
    return value


def read_limited(stream: BinaryIO, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> bytes:
    """Read a binary stream to its end, refusing it as soon as it exceeds ``max_bytes``
    (see :func:`effective_max_bytes`).

    At most ``max_bytes`` plus one chunk is ever held in memory.
    """
    max_bytes = effective_max_bytes(max_bytes, path=path)
    chunks: list[bytes] = []
    total = 0
    while True:
        chunk = stream.read(min(_CHUNK, max_bytes + 1 - total) or 1)
        if not chunk:
            return b"".join(chunks)
        total += len(chunk)
        if total > max_bytes:
            raise too_big_error(path, max_bytes)
        chunks.append(chunk)


def read_file(path: str | Path, *, max_bytes: int = DEFAULT_MAX_BYTES) -> bytes:
    """The bytes of a regular file, checking its size before reading it. Folders, pipes,
    devices and sockets are refused (``io-error``) without blocking."""
    shown = str(path)
    max_bytes = effective_max_bytes(max_bytes, path=shown)
    try:
        with open_regular(path) as stream:
            size = os.fstat(stream.fileno()).st_size
            if size > max_bytes:
                raise too_big_error(shown, max_bytes)
            return read_limited(stream, path=shown, max_bytes=max_bytes)
    except XmlReadError:
        raise
    except (NotARegularFile, FileNotFoundError) as error:
        why = "it does not exist" if isinstance(error, FileNotFoundError) else error.strerror
        raise XmlReadError(
            "io-error",
            f"cannot read the file: {why}",
            location=SourceLocation(shown),
            hint="give the path of a spec file (XPDL or BPMN); specs are not read from "
            "folders, pipes or devices",
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise XmlReadError(
            "io-error",
            f"cannot read the file: {reason}",
            location=SourceLocation(shown),
            hint="check the path and its permissions",
        ) from None


def too_big_error(path: str, max_bytes: int) -> XmlReadError:
    # Line 1: the file as a whole is refused, before any of it is parsed.
    return XmlReadError(
        "too-big",
        f"the file is larger than the limit of {max_bytes:,} bytes, so it was not read",
        location=SourceLocation(path, 1),
        hint="split the package into several files referenced as ExternalPackages, or raise "
        f"the limit: set the environment variable {MAX_BYTES_VARIABLE} to a number of "
        "bytes",
    )
