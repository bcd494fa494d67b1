"""The figures' matplotlib is imported without its ``set()`` docstrings
(``opspec.evaluation.matplotlib_import``): the figures must not change, nor must matplotlib's behaviour
for anyone else in the process."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

# In a fresh interpreter (matplotlib not yet imported): the figure's bytes, whether artists'
# set() still takes every property, and whether a class defined afterwards (a user's own
# artist) gets its generated docstring as usual.
_DRAW = """
import sys
from pathlib import Path
from opspec.evaluation import plots
if sys.argv[1] == "plain":       # matplotlib imported as anyone imports it, before opspec
    import matplotlib.figure, matplotlib.backends.backend_agg, matplotlib.backends.backend_svg
# the report's first figure imports matplotlib's ticker before anything else of it
plots.rates_figure([("missed", 0.0034, 0.001, 0.008)], Path(sys.argv[2] + ".rates.svg"))
plots.per_user_figure({"missed rate": [0.0, 0.0, 1 / 120, 2 / 120, 0.0],
                       "report latency, mean per user": [110.0, 130.5, 99.0, 150.25, 121.0]},
                      Path(sys.argv[2]), units={"missed rate": "%",
                                                "report latency, mean per user": "s"})
from matplotlib.lines import Line2D
# the figures' own way in skipped the docstrings (the light import was used), or not
assert ("linewidth" in (Line2D.set.__doc__ or "")) == (sys.argv[1] == "plain")
line = Line2D([0, 1], [0, 1])
line.set(color="red", linewidth=3, alpha=0.5)
assert (line.get_color(), line.get_linewidth(), line.get_alpha()) == ("red", 3, 0.5)
try:
    line.set(no_such_property=1)
except AttributeError:
    pass
else:
    raise AssertionError("set() accepted an unknown property")
class Mine(Line2D):
    pass
assert "linewidth" in (Mine.set.__doc__ or ""), "a later class lost its set() docstring"
"""


def _draw(mode: str, path: Path) -> bytes:
    subprocess.run([sys.executable, "-c", _DRAW, mode, str(path)], check=True,
                   capture_output=True, text=True)
    return path.read_bytes() + Path(f"{path}.rates.svg").read_bytes()


def test_light_import_draws_the_same_bytes_and_leaves_matplotlib_working(tmp_path: Path
                                                                         ) -> None:
    light = _draw("light", tmp_path / "light.svg")
    plain = _draw("plain", tmp_path / "plain.svg")
    assert light.startswith(b"<?xml")
    assert light == plain
