"""The report's figures laid out from their texts' sizes, measured once, without drawing.

matplotlib's constrained layout finds each axes' decorations (tick labels, axis labels,
titles, legends) by laying out the whole axes as for drawing — every tick made and
measured, for every axes, twice — and the drawing then does it all again: for the report's
six figures that layout was a third of their CPU (docs/engine-performance.md, seventh pass).
Here the same margins come from the texts alone: each tick label's string (the axis' own
locator and formatter, as the drawing will ask them) measured by the renderer the figure is
drawn with, the axis labels', titles' and legends' extents, the ticks' lengths and pads;
then the figure's subplot parameters are set so that, with the same padding as the
constrained layout's, nothing reaches past the figure or into a neighbouring panel. The
measure is repeated with the axes where the first placed them, as the constrained layout
does (a shorter axis may get other ticks), until nothing moves.

Only figures on one grid of plain axes are laid out here (every figure this package draws);
:func:`lay_out` says False for any other, and the caller uses the constrained layout.
``tests/evaluation_output/test_figure_layout.py`` draws every kind of figure, long labels
too, and checks on the drawn figure that no text leaves it or overlaps another.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.axis import Axis
    from matplotlib.figure import Figure

__all__ = ["lay_out"]

#: Space between a decoration and the figure's edge, and on each side of a gap between two
#: panels' decorations, in points: the constrained layout's ``w_pad``/``h_pad`` (3 pt).
PAD = 3.0
#: At most this many measures: the first with the axes where matplotlib put them, each
#: next with the axes where the one before placed them (a shorter axis may get other ticks;
#: a label longer than its axis is centred on it), until nothing moves by a pixel.
PASSES = 4
#: The least gap between panels, as a fraction of the figure: its ``wspace``/``hspace``.
SPACE = 0.02


def lay_out(fig: Figure) -> bool:
    """Set ``fig``'s subplot parameters from its texts' measured sizes; False (nothing
    changed) when ``fig`` is not one grid of plain axes."""
    grid = _grid(fig)
    if grid is None:
        return False
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    try:
        for _ in range(PASSES):
            before = fig.subplotpars.left, fig.subplotpars.right, fig.subplotpars.bottom, \
                fig.subplotpars.top
            if not _place(fig, grid, renderer):
                return False
            after = fig.subplotpars.left, fig.subplotpars.right, fig.subplotpars.bottom, \
                fig.subplotpars.top
            moved = max(abs(a - b) for a, b in zip(before, after, strict=True))
            if moved * max(fig.bbox.width, fig.bbox.height) < 1.0:
                break
        return True
    finally:
        _MEASURED.pop(id(renderer), None)


def _grid(fig: Figure) -> tuple[int, int, list[tuple[Axes, int, int]]] | None:
    """(rows, columns, [(axes, row, column)]) of a figure whose axes each fill one cell of
    one grid, else None."""
    axes = fig.get_axes()
    if not axes:
        return None
    cells = []
    gridspec = None
    for ax in axes:
        spec = ax.get_subplotspec()
        if spec is None or type(ax).__name__ != "Axes":
            return None
        if gridspec is None:
            gridspec = spec.get_gridspec()
        if spec.get_gridspec() is not gridspec or len(spec.rowspan) != 1 \
                or len(spec.colspan) != 1:
            return None
        cells.append((ax, spec.rowspan.start, spec.colspan.start))
    assert gridspec is not None
    rows, columns = gridspec.get_geometry()
    if gridspec.get_width_ratios() is not None and len(set(gridspec.get_width_ratios())) > 1:
        return None
    if gridspec.get_height_ratios() is not None \
            and len(set(gridspec.get_height_ratios())) > 1:
        return None
    return rows, columns, cells


def _place(fig: Figure, grid: tuple[int, int, list[tuple[Axes, int, int]]], renderer: Any
           ) -> bool:
    rows, columns, cells = grid
    width, height = fig.bbox.width, fig.bbox.height
    points = fig.dpi / 72.0
    pad = PAD * points
    left = [0.0] * columns
    right = [0.0] * columns
    top = [0.0] * rows
    bottom = [0.0] * rows
    for ax, row, column in cells:
        extents = _extents(ax, renderer, points)
        if extents is None:
            return False
        l_, r_, b_, t_ = extents
        left[column] = max(left[column], l_)
        right[column] = max(right[column], r_)
        bottom[row] = max(bottom[row], b_)
        top[row] = max(top[row], t_)
    # what the figure itself holds below and above its panels: a note (supxlabel), texts
    # put on the figure at its bottom (the count of values left out)
    below, above = _figure_texts(fig, renderer, pad)
    margin_left = left[0] + pad
    margin_right = right[-1] + pad
    margin_bottom = bottom[-1] + pad + below
    margin_top = top[0] + pad + above
    gap_x = max([right[c] + left[c + 1] + 2 * pad for c in range(columns - 1)]
                + [SPACE * width])
    gap_y = max([bottom[r] + top[r + 1] + 2 * pad for r in range(rows - 1)]
                + [SPACE * height])
    cell_w = (width - margin_left - margin_right - (columns - 1) * gap_x) / columns
    cell_h = (height - margin_bottom - margin_top - (rows - 1) * gap_y) / rows
    if cell_w <= 0.1 * width / columns or cell_h <= 0.1 * height / rows:
        return False            # decorations larger than the figure: let matplotlib try
    fig.subplots_adjust(left=margin_left / width, right=1.0 - margin_right / width,
                        bottom=margin_bottom / height, top=1.0 - margin_top / height,
                        wspace=gap_x / cell_w if columns > 1 else 0.0,
                        hspace=gap_y / cell_h if rows > 1 else 0.0)
    return True


def _extents(ax: Axes, renderer: Any, points: float
             ) -> tuple[float, float, float, float] | None:
    """How far (pixels) ``ax``'s decorations reach past its box: left, right, bottom, top;
    None for an axes this layout does not know."""
    box = ax.get_window_extent(renderer)
    left = right = bottom = top = 0.0
    # the title (and the left and right ones): above the box by the title's pad
    title_pad = float(_rc("axes.titlepad")) * points
    for title in _titles(ax):
        top = max(top, title_pad + _size(title, renderer)[1])
    if ax.axison:
        x = _axis_extents(ax.xaxis, "bottom", "top", box, renderer, points)
        y = _axis_extents(ax.yaxis, "left", "right", box, renderer, points)
        if x is None or y is None:
            return None
        (bottom_x, top_x, left_x, right_x), (left_y, right_y, bottom_y, top_y) = x, y
        left = max(left, left_y, left_x)
        right = max(right, right_y, right_x)
        bottom = max(bottom, bottom_x, bottom_y)
        top = max(top + top_x, top_y)
    legend = ax.get_legend()
    if legend is not None and legend.get_visible() and legend.get_in_layout():
        extent = legend.get_window_extent(renderer)
        left = max(left, box.x0 - extent.x0)
        right = max(right, extent.x1 - box.x1)
        bottom = max(bottom, box.y0 - extent.y0)
        top = max(top, extent.y1 - box.y1)
    for text in ax.texts:           # annotations: inside the axes as drawn, but not always
        if not (text.get_visible() and text.get_in_layout() and text.get_text()) \
                or _far_inside(text, box, points):
            continue
        extent = text.get_window_extent(renderer)
        left = max(left, box.x0 - extent.x0)
        right = max(right, extent.x1 - box.x1)
        bottom = max(bottom, box.y0 - extent.y0)
        top = max(top, extent.y1 - box.y1)
    return left, right, bottom, top


def _axis_extents(axis: Axis, low: str, high: str, box: Any, renderer: Any, points: float
                  ) -> tuple[float, float, float, float] | None:
    """How far an axis' ticks, tick labels, offset text and label reach past the axes box:
    on its own side (``low``: bottom or left), on the other side, and along it (each end),
    as ``(own side, other side, before its start, after its end)``; None when its tick
    labels are on the other side (not drawn by this package)."""
    name = axis.axis_name      # "x" or "y"
    params = axis.get_tick_params()
    if params.get(f"label{high}", _rc(f"{name}tick.label{high}")) \
            or params.get(high, False) and _rc(f"{name}tick.direction") != "in":
        return None
    where = axis.axes.spines[low].get_position()
    if where[0] != "outward":
        return None
    offset = float(where[1]) * points
    length = float(params.get("length", _rc(f"{name}tick.major.size"))) * points
    tick_pad = float(params.get("pad", _rc(f"{name}tick.major.pad"))) * points
    ticks_out = params.get(low, True) and _rc(f"{name}tick.direction") != "in"
    own = offset + (length if ticks_out else 0.0)
    before = after = other = 0.0
    labels_on = params.get(f"label{low}", _rc(f"{name}tick.label{low}"))
    label_size = params.get("labelsize", _rc(f"{name}tick.labelsize"))
    shown = _tick_labels(axis) if labels_on else []
    if shown:
        from matplotlib.font_manager import FontProperties

        prop = FontProperties(size=label_size)
        sizes = [(at, *_measure(axis.axes, renderer, text, prop)) for at, text in shown]
        span = (box.x0, box.x1) if name == "x" else (box.y0, box.y1)
        # across the axis: the widest (y) or tallest (x) label; along it, what a label
        # centred on a tick near an end reaches past that end
        across = max((w if name == "y" else h) for _, w, h in sizes)
        own += tick_pad + across
        for fraction, w, h in sizes:
            at = span[0] + fraction * (span[1] - span[0])
            half = (h if name == "y" else w) / 2.0
            before = max(before, span[0] - (at - half))
            after = max(after, at + half - span[1])
    offset_text = axis.get_major_formatter().get_offset() if shown else ""
    if offset_text:
        from matplotlib.font_manager import FontProperties

        w, h = _measure(axis.axes, renderer, offset_text, FontProperties(size=label_size))
        # x: under the tick labels at the right end; y: above the axis at its top
        if name == "x":
            own += h + tick_pad
        else:
            after = max(after, h + tick_pad)
    label = axis.label
    if label.get_visible() and label.get_text():
        w, h = _size(label, renderer)
        own += float(axis.labelpad) * points + (h if name == "x" else w)
        # centred on the axis: a label longer than the axis reaches past both its ends
        length_px = box.width if name == "x" else box.height
        half_over = ((w if name == "x" else h) - length_px) / 2.0
        before, after = max(before, half_over), max(after, half_over)
    return own, other, before, after


def _far_inside(text: Any, box: Any, points: float) -> bool:
    """Whether an annotation at data coordinates lies so far inside the axes box that its
    text cannot reach its edge (no glyph is wider than its font size, an em): then it need
    not be measured."""
    from matplotlib.text import Annotation

    if not isinstance(text, Annotation) or text.xycoords != "data" or "\n" in text.get_text():
        return False
    ax = text.axes
    x, y = ax.transData.transform(text.xy)
    offset = 0.0
    if text.anncoords == "offset points":
        offset = max(abs(float(v)) for v in text.xyann) * points
    reach = (len(text.get_text()) + 1) * float(text.get_fontsize()) * points + offset
    return bool(box.x0 + reach < x < box.x1 - reach and box.y0 + reach < y < box.y1 - reach)


def _tick_labels(axis: Axis) -> list[tuple[float, str]]:
    """The major tick labels the drawing will show — (place along the axis as a fraction of
    it, text) — from the axis' own locator and formatter, without making tick artists."""
    import numpy as np

    low, high = sorted(axis.get_view_interval())
    if not high > low:
        return []
    locs = np.asarray(axis.get_majorticklocs(), dtype=float)
    transform = axis.get_transform()
    a, b = transform.transform([low, high])
    if not b > a:
        return []
    inside = [v for v in locs if low - 1e-9 * (high - low) <= v <= high + 1e-9 * (high - low)]
    texts = axis.get_major_formatter().format_ticks(inside)
    return [(float((transform.transform([v])[0] - a) / (b - a)), t)
            for v, t in zip(inside, texts, strict=True) if t]


def _titles(ax: Axes) -> list[Any]:
    """The axes' titles that have a text (centre, left, right)."""
    from matplotlib.text import Text

    own = set(map(id, ax.texts))
    return [child for child in ax.get_children() if isinstance(child, Text)
            and id(child) not in own and child.get_visible() and child.get_text()]


def _figure_texts(fig: Figure, renderer: Any, pad: float) -> tuple[float, float]:
    """Height the figure's own texts need below and above the panels (its supxlabel, a
    suptitle, texts put on the figure near its bottom or top)."""
    below = above = 0.0
    height = fig.bbox.height
    texts = [*fig.texts]
    for text in (getattr(fig, "_supxlabel", None), getattr(fig, "_suptitle", None)):
        if text is not None:
            texts.append(text)
    for text in texts:
        if not (text.get_visible() and text.get_in_layout() and text.get_text()):
            continue
        extent = text.get_window_extent(renderer)
        if extent.y1 <= height / 2:
            below = max(below, extent.y1 + pad)
        else:
            above = max(above, height - extent.y0 + pad)
    return below, above


def _size(text: Any, renderer: Any) -> tuple[float, float]:
    extent = text.get_window_extent(renderer)
    return float(extent.width), float(extent.height)


def _measure(ax: Axes, renderer: Any, text: str, prop: Any) -> tuple[float, float]:
    """Width and height (pixels) of one tick label's text, as the drawing measures it: a
    line of text's width, and its height but at least that of "lp" (matplotlib's text
    layout); a text with mathtext or several lines through a text artist, never drawn."""
    key = (text, prop.get_size_in_points())
    cache = _MEASURED.setdefault(id(renderer), {})
    if key in cache:
        return cache[key]
    if "$" in text or "\n" in text:
        from matplotlib.text import Text

        probe = Text(0.0, 0.0, text, fontproperties=prop)
        probe.set_figure(ax.get_figure(root=True))
        size = _size(probe, renderer)
    else:
        w, h, _ = renderer.get_text_width_height_descent(text, prop, ismath=False)
        lp = cache.get(("lp", key[1]))
        if lp is None:
            lp = cache[("lp", key[1])] = renderer.get_text_width_height_descent(
                "lp", prop, ismath=False)[1:]
        size = (float(w), float(max(h, lp[0])))
    cache[key] = size
    return size


#: Tick labels measured, by renderer (a figure's, while it is laid out: :func:`lay_out`
#: empties it) and (text, size).
_MEASURED: dict[int, dict[Any, Any]] = {}


def _rc(name: str) -> Any:
    import matplotlib

    return matplotlib.rcParams[name]
