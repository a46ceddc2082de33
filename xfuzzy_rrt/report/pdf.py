"""``xfuzzy-rrt report DIR --pdf``: the overview and its certification evidence as a PDF.

Why headless Chromium: the pages are drawn by plotly.js, so only a browser prints them as a
reader sees them. Chromium's own ``--print-to-pdf`` needs no Python package; the overview draws
every figure at load (``Page(eager=True)``) and ``--virtual-time-budget`` lets those scripts
finish before printing. Install: Debian/Ubuntu ``apt-get install chromium`` (CI does), or point
``XFUZZY_CHROMIUM`` at any Chromium/Chrome binary.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from xfuzzy_rrt.errors import InputError

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
TIMEOUT_S = 180
#: A4 landscape (297 mm) less two 10 mm margins, in CSS pixels (96 per inch).
PRINT_WIDTH_PX = 1046


def find_chromium() -> str:
    """The browser binary (``XFUZZY_CHROMIUM`` first), or an ``InputError`` saying how to get one."""
    env = os.environ.get("XFUZZY_CHROMIUM")
    if env:
        if Path(env).is_file():
            return env
        raise InputError("XFUZZY_CHROMIUM", f"{env}: no such file")
    for name in CANDIDATES:
        found = shutil.which(name)
        if found:
            return found
    raise InputError("--pdf", "needs Chromium to print the report (Debian/Ubuntu: apt-get "
                     "install chromium; or set XFUZZY_CHROMIUM to a Chromium/Chrome binary)")


def print_pdf(html: Path, pdf: Path, browser: str | None = None) -> None:
    """Print ``html`` (a local page) to ``pdf`` with headless Chromium; ``pdf`` appears only
    when printing succeeded."""
    from xfuzzy_rrt.atomic import atomic_path

    browser = browser or find_chromium()
    with atomic_path(pdf) as tmp:
        cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu",
               "--disable-background-networking", "--disable-component-update", "--no-first-run",
               "--disable-sync", "--no-pdf-header-footer", "--virtual-time-budget=20000",
               # Lay the page out at the printed width (A4 landscape less 10 mm margins), so
               # that plotly sizes its figures for the paper, not for a screen.
               f"--window-size={PRINT_WIDTH_PX},1400",
               "--run-all-compositor-stages-before-draw", f"--print-to-pdf={tmp}",
               Path(html).resolve().as_uri()]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            raise InputError(str(pdf), f"Chromium did not finish printing within {TIMEOUT_S} s") \
                from None
        if proc.returncode != 0 or not tmp.is_file() or tmp.stat().st_size < 1000:
            last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            raise InputError(str(pdf), f"Chromium could not print the report: {last}")
