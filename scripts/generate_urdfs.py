"""Regenerate ``urdf/``: the robots robodyn generates, with default parameters.

Run from the repository root: ``python scripts/generate_urdfs.py``. A test checks that each
committed file equals the generator's output.
"""

from pathlib import Path

from robodyn.urdf.models import GENERATED

FOLDER = Path(__file__).resolve().parent.parent / "urdf"


def main() -> None:
    """Write every generated robot's URDF (``urdf/rp_arm.urdf``, ``urdf/pendulum.urdf``)."""
    FOLDER.mkdir(exist_ok=True)
    for name, generate in GENERATED.items():
        target = FOLDER / f"{name}.urdf"
        target.write_text(generate(), encoding="utf-8")
        print(f"wrote {target}")


if __name__ == "__main__":
    main()
