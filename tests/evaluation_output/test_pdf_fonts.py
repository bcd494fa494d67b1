"""``--figures pdf`` is for a paper: its fonts are embedded TrueType, not Type 3, which
publishers' PDF checks (IEEE PDF eXpress, ACM's) refuse; matplotlib writes Type 3 unless
told otherwise, and the figures were Type 3."""

from __future__ import annotations

import re
from pathlib import Path

from opspec.evaluation import figure_files, plots


def test_a_pdf_figure_embeds_truetype_fonts_not_type3(tmp_path: Path) -> None:
    with figure_files.figure_format("pdf"):
        plots.rates_figure([("missed rate", 0.0029, 0.0022, 0.0039)], tmp_path / "r.pdf")
    data = (tmp_path / "r.pdf").read_bytes()
    subtypes = set(re.findall(rb"/Subtype\s*/(\w+)", data))
    assert b"Type3" not in subtypes
    assert b"CIDFontType2" in subtypes or b"TrueType" in subtypes
    assert b"/FontFile2" in data                 # the font program is in the file
