"""Regenerate docs/derivation_rp_arm_1.png and _2.png: the RP arm's derivation, first pages.

Run from the repository root: ``python scripts/make_derivation_pictures.py``. Needs pdflatex
and pdftoppm (Debian's texlive-latex-base and poppler-utils; ``make tex`` installs both).
Each picture is a page of the PDF that
``robodyn equations rp_arm --derivation --keep-params --format pdf`` writes (the lecture's
symbols), rasterised and cropped to its text (the page number left out).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, ImageOps

from robodyn.cli.app import main as robodyn

ROOT = Path(__file__).resolve().parent.parent
#: How many pages become pictures.
PAGES = 2
#: Resolution of the pictures, in [dpi].
DPI = 100


def crop(page_png: Path, target: Path) -> None:
    """``page_png`` cropped to its text (8 px margin), without the page number, into ``target``."""
    page = Image.open(page_png).convert("L")
    body = page.crop((0, 0, page.width, int(page.height * 0.93)))
    box = ImageOps.invert(body).getbbox()
    page.crop((box[0] - 8, box[1] - 8, box[2] + 8, box[3] + 8)).save(target, optimize=True)


def main() -> None:
    """Write the pictures into docs/."""
    missing = [tool for tool in ("pdflatex", "pdftoppm") if shutil.which(tool) is None]
    if missing:
        sys.exit(f"needs {' and '.join(missing)} (make tex installs them)")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        pdf = folder / "derivation.pdf"
        if robodyn(["equations", "rp_arm", "--derivation", "--keep-params", "--format", "pdf", "--out", str(pdf)]) != 0:
            raise SystemExit("robodyn could not typeset the RP arm's derivation")
        subprocess.run(
            ["pdftoppm", "-png", "-r", str(DPI), "-f", "1", "-l", str(PAGES), str(pdf), str(folder / "page")], check=True
        )
        for number, page in enumerate(sorted(folder.glob("page*.png")), 1):
            target = ROOT / "docs" / f"derivation_rp_arm_{number}.png"
            crop(page, target)
            print(f"wrote {target.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
