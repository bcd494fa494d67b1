"""The evaluation report as a reader sees it: rendered by a real headless browser (Chromium).

The screenshot must be a real picture (not blank) and every figure in the page must have
decoded (no broken images). Chromium comes from scripts/system-deps.sh (which CI runs); where
it is missing the test runs that script once, and skips only when it still cannot be had.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def _browser(chromium: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                           "--hide-scrollbars", "--no-first-run", "--disable-extensions",
                           *args], capture_output=True, text=True, timeout=120, check=False)


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("browser") / "run"
    status = main(["evaluate", str(SPEC), "--users", "40", "--days", "3", "--workers", "1",
                   "--out", str(out), "--quiet", "--json"])
    assert status == 0
    return out / "report.html"


def test_the_report_renders_in_a_headless_browser(chromium: str, report: Path,
                                                  tmp_path: Path) -> None:
    from PIL import Image, ImageStat

    shot = tmp_path / "report.png"
    done = _browser(chromium, f"--screenshot={shot}", "--window-size=1200,3000",
                    report.as_uri())
    assert shot.is_file(), done.stderr[-2000:]
    with Image.open(shot) as image:
        assert image.size == (1200, 3000)
        grey = image.convert("L")
        stat = ImageStat.Stat(grey)
        # not blank: plenty of ink (text, tables, figures) on the white page
        assert stat.stddev[0] > 20, f"the screenshot looks blank (sd {stat.stddev[0]:.1f})"
        dark = sum(grey.histogram()[:128]) / (image.size[0] * image.size[1])
        assert dark > 0.01, f"only {dark:.2%} of the screenshot is ink"


def test_every_figure_in_the_report_decodes_in_the_browser(chromium: str, report: Path,
                                                           tmp_path: Path) -> None:
    # the report has no script; a copy gets one that counts figures the browser did not
    # draw: an inline SVG (the report's default) laid out with no size or nothing in it, an
    # image that failed to decode
    probe = tmp_path / "probe.html"
    html = report.read_text(encoding="utf-8")
    script = ("<script>window.addEventListener('load', () => {"
              "const imgs = [...document.images];"
              "const svgs = [...document.querySelectorAll('figure svg')];"
              "const broken = imgs.filter(i => !i.complete || i.naturalWidth === 0).length"
              " + svgs.filter(s => { const r = s.getBoundingClientRect();"
              " return r.width < 100 || r.height < 50"
              " || s.querySelectorAll('path, use').length === 0; }).length;"
              "document.body.setAttribute('data-probe', "
              "`images=${imgs.length + svgs.length} broken=${broken}`);});</script>")
    probe.write_text(html.replace("</body>", script + "</body>"), encoding="utf-8")
    done = _browser(chromium, "--virtual-time-budget=10000", "--dump-dom", probe.as_uri())
    found = re.search(r'data-probe="images=(\d+) broken=(\d+)"', done.stdout)
    assert found, f"the page did not load: {done.stderr[-2000:]}"
    images, broken = int(found.group(1)), int(found.group(2))
    assert images == html.count("<img ") + html.count("<svg") and images >= 6
    assert broken == 0, f"{broken} of {images} figures did not decode"
