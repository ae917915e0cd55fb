"""Regenerate the README's pictures in docs/: the demo's poster and filmstrip, a what-if plot.

    .venv/bin/python scripts/make_pictures.py          # needs Chromium (make chromium)

The pictures come from the demo the Makefile runs (the RP arm driven by the task-space
controller to the target 0.7, 0.7, its first second) and the default what-if sweep with a 10 N downward
force. docs/pictures.json records a hash of the inputs (the code that draws them) and of
each picture; tests/integration/test_pictures.py fails when the inputs changed since, or a picture
was edited by hand: then run this script again.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
DOCS = ROOT / "docs"
PICTURES = ("rp_arm_poster.png", "rp_arm_filmstrip.png", "rp_arm_whatif.png")
#: What the pictures depend on (relative to the repository root).
INPUTS = (
    "robodyn/viz",
    "robodyn/sim/experiment.py",
    "robodyn/sim/control.py",
    "robodyn/sim/whatif.py",
    "robodyn/urdf/models",
    "scripts/make_pictures.py",
)


def inputs_hash(root: Path = ROOT) -> str:
    """SHA-256 over the input files' paths and contents (in path order)."""
    digest = hashlib.sha256()
    for entry in INPUTS:
        path = root / entry
        files = sorted(p for p in path.rglob("*.py")) if path.is_dir() else [path]
        for file in files:
            digest.update(str(file.relative_to(root)).encode() + b"\0" + file.read_bytes() + b"\0")
    return digest.hexdigest()


def file_hash(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def main() -> None:
    import robodyn
    from robodyn.sim.experiment import run_simulation
    from robodyn.sim.whatif import sweep
    from robodyn.viz.plots import plot_whatif
    from robodyn.viz.recording import recording

    robot = robodyn.load("rp_arm")
    trajectory, summary = run_simulation(
        robot, controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1], duration=1.0
    )
    made = recording(robot, trajectory, target=summary["target_m"])
    made.still(DOCS / "rp_arm_poster.png", at=made.duration)  # the poster: the final pose, the whole path drawn
    made.filmstrip(DOCS / "rp_arm_filmstrip.png", 5, size=(320, 240))
    rows = sweep("rp_arm", forces=((0.0, 0.0, 0.0), (0.0, 0.0, -10.0)))
    plot_whatif(rows, robot.joint_names, [dof.effort_unit for dof in robot.dofs], DOCS / "rp_arm_whatif.png",
                effort_limits=[joint.effort for joint in robot.joints])  # fmt: skip
    record = {"inputs_sha256": inputs_hash(), "pictures": {name: file_hash(DOCS / name) for name in PICTURES}}
    (DOCS / "pictures.json").write_text(json.dumps(record, indent=2) + "\n")
    for name in PICTURES:
        print(f"wrote docs/{name}")


if __name__ == "__main__":
    main()
