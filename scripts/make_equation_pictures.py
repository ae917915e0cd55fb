"""Regenerate docs/equations_rp_arm.png and docs/equations_rrp_arm.png: the typeset equations.

Run from the repository root: ``python scripts/make_equation_pictures.py``. Needs pdflatex
and pdftoppm (Debian's texlive-latex-base and poppler-utils; ``make tex`` installs both).
Each picture is the PDF that ``robodyn equations MODEL --symbolic --format pdf`` writes,
rasterised and cropped to its text (the page number left out).
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
MODELS = {"rp_arm": "rp_arm", "rrp_arm": str(ROOT / "tests" / "data" / "rrp_arm.urdf")}


def picture(model: str, target: Path, folder: Path) -> None:
    """Typeset ``model``'s equations into ``target`` (PNG, cropped, 8 px margin)."""
    pdf = folder / f"{target.stem}.pdf"
    if robodyn(["equations", model, "--symbolic", "--format", "pdf", "--out", str(pdf)]) != 0:
        raise SystemExit(f"robodyn could not typeset {model}")
    subprocess.run(["pdftoppm", "-png", "-r", "110", "-singlefile", str(pdf), str(folder / target.stem)], check=True)
    page = Image.open(folder / f"{target.stem}.png").convert("L")
    body = page.crop((0, 0, page.width, int(page.height * 0.9)))  # leave out the page number
    box = ImageOps.invert(body).getbbox()
    page.crop((box[0] - 8, box[1] - 8, box[2] + 8, box[3] + 8)).save(target, optimize=True)


def main() -> None:
    """Write both pictures into docs/."""
    missing = [tool for tool in ("pdflatex", "pdftoppm") if shutil.which(tool) is None]
    if missing:
        sys.exit(f"needs {' and '.join(missing)} (make tex installs them)")
    with tempfile.TemporaryDirectory() as folder:
        for name, model in MODELS.items():
            target = ROOT / "docs" / f"equations_{name}.png"
            picture(model, target, Path(folder))
            print(f"wrote {target.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
