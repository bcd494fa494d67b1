"""Handlers that build the immutable model from a normalised XPDL tree.

One small module per family (data, resources, events, activity bodies, activities, processes,
package); dispatch on element names goes through the registries in :mod:`.registry`.
"""

from opspec.xpdl.handlers.common import BuildContext
from opspec.xpdl.handlers.package import build_package

__all__ = ["BuildContext", "build_package"]
