"""Regenerate ``urdf/rp_arm.urdf``, the RP arm with default parameters.

Run from the repository root: ``python scripts/generate_rp_arm.py``. A test checks that the
committed file equals the generator's output.
"""

from pathlib import Path

from robodyn.models import rp_arm_urdf

TARGET = Path(__file__).resolve().parent.parent / "urdf" / "rp_arm.urdf"


def main() -> None:
    """Write the default RP arm's URDF."""
    TARGET.parent.mkdir(exist_ok=True)
    TARGET.write_text(rp_arm_urdf(), encoding="utf-8")
    print(f"wrote {TARGET}")


if __name__ == "__main__":
    main()
