"""Check every robot of the zoo against the reference and write ``docs/zoo.md``.

Run from the repository root: ``python scripts/zoo_report.py``. Each fixed-base robot is
loaded and compared with :func:`robodyn.verify.check.check_robot`; a robot that cannot be compared
is listed with the reason. The slow test tier re-runs this and compares it with the file.
"""

from __future__ import annotations

import sys
from pathlib import Path

from robodyn.verify.zoo_status import zoo_markdown, zoo_statuses

TARGET = Path(__file__).resolve().parent.parent / "docs" / "zoo.md"


def main() -> int:
    """Write the zoo listing; exit status 1 if any robot that should pass fails."""
    statuses = zoo_statuses(progress=lambda name: print(f"checking {name}", file=sys.stderr))
    TARGET.write_text(zoo_markdown(statuses), encoding="utf-8")
    print(f"wrote {TARGET}")
    return 1 if any(status.status == "fail" for status in statuses) else 0


if __name__ == "__main__":
    sys.exit(main())
