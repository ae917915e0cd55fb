"""Check every robot of the zoo against the reference and write ``docs/zoo.md``.

Run from the repository root: ``python scripts/zoo_report.py``. Each fixed-base robot is
loaded and compared with :func:`robodyn.verify.check.check_robot`; a robot that cannot be compared
is listed with the reason. The slow test tier re-runs this and compares it with the file.

``--scheduler ADDRESS|local:N`` checks one robot a Dask task (``robodyn[scale]``); the
listing is the same.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from robodyn.urdf.zoo import zoo_names
from robodyn.verify.zoo_status import zoo_markdown, zoo_status, zoo_statuses

TARGET = Path(__file__).resolve().parent.parent / "docs" / "zoo.md"


def main(argv: list[str] | None = None) -> int:
    """Write the zoo listing; exit status 1 if any robot that should pass fails."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scheduler", metavar="ADDRESS|local:N", help="check the robots on Dask workers")
    parser.add_argument("--out", type=Path, default=TARGET, help=f"listing to write (default {TARGET})")
    parser.add_argument("--only", help="comma-separated zoo names (default: the whole zoo)")
    arguments = parser.parse_args(argv)
    names = arguments.only.split(",") if arguments.only else zoo_names()
    unknown = sorted(set(names) - set(zoo_names()))
    if unknown:
        parser.error(f"not zoo robots: {', '.join(unknown)}")
    if arguments.scheduler:
        from robodyn.scale.cluster import connect
        from robodyn.scale.sweeps import zoo_statuses as distributed_statuses

        with connect(arguments.scheduler) as client:
            print(f"checking {len(names)} robots on {arguments.scheduler}", file=sys.stderr)
            statuses = distributed_statuses(client, names)
    elif arguments.only:
        statuses = [zoo_status(name) for name in names]
    else:
        statuses = zoo_statuses(progress=lambda name: print(f"checking {name}", file=sys.stderr))
    arguments.out.write_text(zoo_markdown(statuses), encoding="utf-8")
    print(f"wrote {arguments.out}")
    return 1 if any(status.status == "fail" for status in statuses) else 0


if __name__ == "__main__":
    sys.exit(main())
