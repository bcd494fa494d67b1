"""Where and how a figure is written: the format (vector SVG, the report's default, which
the HTML report inlines; vector PDF, with an SVG twin beside it for the HTML report; PNG at
:data:`DPI`), the panels laid out once before the drawing, and bytes that are the same for
the same results (no dates in the files).

Every figure function ends with :func:`save`; :func:`figure_format` chooses the format for a
block of them, else the one the path's suffix names.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import TYPE_CHECKING

from opspec.errors import EvaluationError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DPI", "FORMATS", "chosen_format", "figure_format", "save", "written_as"]

#: Resolution of PNG figures (journals ask for at least 200-300 dpi for line art in raster).
DPI = 200
#: What ``opspec evaluate --figures`` can write: vector SVG (the default; inlined in the HTML
#: report), vector PDF (for LaTeX), or PNG at :data:`DPI`.
FORMATS = ("svg", "pdf", "png")
#: The format :func:`figure_format` chose; None: the one ``path``'s suffix names (PNG for an
#: unknown suffix).
_FORMAT: ContextVar[str | None] = ContextVar("opspec_figure_format", default=None)


@contextmanager
def figure_format(name: str) -> Iterator[None]:
    """Within this block, figures are written as ``name`` (one of :data:`FORMATS`)."""
    if name not in FORMATS:
        raise EvaluationError(f"unknown figure format {name!r}",
                              hint="use " + ", ".join(FORMATS))
    token = _FORMAT.set(name)
    try:
        yield
    finally:
        _FORMAT.reset(token)


def chosen_format() -> str | None:
    """The format :func:`figure_format` chose for the block this is called in (None: the
    one each path's suffix names)."""
    return _FORMAT.get()


def written_as(path: Path) -> tuple[Path, str]:
    """The file a figure asked to be written at ``path`` is written to, and its format."""
    fmt = _FORMAT.get() or (Path(path).suffix.lstrip(".").lower() or "png")
    if fmt not in FORMATS:
        fmt = "png"
    return Path(path).with_suffix(f".{fmt}"), fmt


def save(fig: Figure, path: Path) -> Path:
    """Write ``fig`` to ``path`` in the format chosen (see the module docstring) and return
    the path written (with PDF, its SVG twin's: the HTML report shows that one)."""
    path, fmt = written_as(path)
    _lay_out(fig)
    fig.patch.set_facecolor("white")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        if fmt == "png":
            _save_png(fig, path)
            return path
        # no dates in the files: the same results give the same bytes
        fig.savefig(path, format=fmt, metadata={"Date": None} if fmt == "svg"
                    else {"CreationDate": None, "ModDate": None})
        if fmt == "pdf":            # the HTML report shows vector figures inline: SVG
            twin = path.with_suffix(".svg")
            fig.savefig(twin, format="svg", metadata={"Date": None})
            return twin
    except OSError as error:
        raise EvaluationError(f"cannot write the figure {path}: {error.strerror or error}",
                              hint="check that the output folder exists, is writable and "
                                   "the disk is not full") from None
    return path


def _lay_out(fig: Figure) -> None:
    """Place the panels so that every text fits: from the texts' measured sizes
    (:mod:`.figure_layout`), or with matplotlib's constrained layout for a figure that
    module does not lay out. Either is done once, before the drawing, which then lays
    nothing out again."""
    from opspec.evaluation.figure_layout import lay_out

    if not lay_out(fig):
        from matplotlib.layout_engine import ConstrainedLayoutEngine

        ConstrainedLayoutEngine().execute(fig)


def _save_png(fig: Figure, path: Path) -> None:
    from PIL import Image

    canvas = fig.canvas
    canvas.draw()
    width, height = canvas.get_width_height(physical=True)
    # RGB rather than matplotlib's RGBA (the background is opaque white: a quarter less to
    # compress), at zlib level 3: half the encoding time of level 6, and files no larger
    # than matplotlib's own RGBA at level 6. The resolution is stored (pHYs) for layout tools.
    image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(),  # type: ignore[attr-defined]
                             "raw", "RGBA", 0, 1).convert("RGB")
    image.save(path, format="png", compress_level=3, dpi=(DPI, DPI))

