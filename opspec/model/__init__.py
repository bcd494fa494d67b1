"""The immutable specification model: frozen dataclasses and tuples, no I/O, no lxml.

Everything the front end reads ends up here; the engine runs these values. A model can be
built in plain Python (tests do) and round-trips through the ``.wfs`` JSON form.
"""

# The public names are each module's own ``__all__``, written once there.
from opspec.model import activities, common, data, expressions, package, process, resources, sisarl
from opspec.model.activities import *  # noqa: F403
from opspec.model.common import *  # noqa: F403
from opspec.model.data import *  # noqa: F403
from opspec.model.expressions import *  # noqa: F403
from opspec.model.package import *  # noqa: F403
from opspec.model.process import *  # noqa: F403
from opspec.model.resources import *  # noqa: F403
from opspec.model.sisarl import *  # noqa: F403

__all__: list[str] = []
__all__ += activities.__all__
__all__ += common.__all__
__all__ += data.__all__
__all__ += expressions.__all__
__all__ += package.__all__
__all__ += process.__all__
__all__ += resources.__all__
__all__ += sisarl.__all__
