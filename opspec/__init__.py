"""opspec: execute operational specifications (XPDL / SISARL-XPDL) of assistive devices and
their users, for usability evaluation, walkthroughs, specification tests and hardware in the loop.

Importing ``opspec`` stays light: no lxml, Textual or pyserial is imported here.
"""

from opspec import _native

_native.install()      # the engine compiled with mypyc, or from source if that build is stale

__version__ = "0.1.0"
__all__ = ["__version__"]
