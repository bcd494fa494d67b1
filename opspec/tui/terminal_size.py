"""The smallest terminal the walkthrough is laid out for, and the line that says so below it.

The layout needs 80 x 24 cells (64 x 20 with ``--large``, laid out for a big font): smaller,
the panels no longer fit above each other (the screen scrolls, the timeline drops off) and the
footer's keys are cut mid-word. A participant at a small terminal is not refused — the session
may already be running, and a window is resized in a moment — but a line at the top says
what size to make it, for as long as the terminal is smaller.
"""

from __future__ import annotations

from textual.geometry import Size
from textual.widgets import Static

__all__ = ["MINIMUM", "MINIMUM_LARGE", "SizeWarning", "too_small"]

MINIMUM = Size(80, 24)
MINIMUM_LARGE = Size(64, 20)       # --large


def too_small(size: Size, *, large: bool) -> str:
    """What the line says at ``size`` ("" when the terminal is big enough)."""
    least = MINIMUM_LARGE if large else MINIMUM
    if size.width >= least.width and size.height >= least.height:
        return ""
    return (f"Terminal {size.width}x{size.height} is too small: make it at least "
            f"{least.width}x{least.height}")


class SizeWarning(Static):
    """The line at the top while the terminal is smaller than the layout needs."""

    DEFAULT_CSS = """
    SizeWarning { dock: top; height: auto; display: none; padding: 0 1;
                  background: $warning; color: $text; text-style: bold; }
    SizeWarning.shown { display: block; }
    """

    def __init__(self, *, large: bool) -> None:
        super().__init__(id="too-small")
        self.large = large

    def fit(self, size: Size) -> None:
        """Show or hide the line for a terminal of ``size``."""
        said = too_small(size, large=self.large)
        self.update(said)
        self.set_class(bool(said), "shown")
