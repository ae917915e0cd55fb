"""Example: the lecture's "what if" questions: link material and payload, in numbers.

Run: ``python scripts/example_whatif.py``.
"""

import robodyn
from robodyn.sim.whatif import sweep, table_text


def main() -> None:
    rows = sweep("rp_arm", materials=("abs", "aluminium", "steel"), payloads=(0.0, 1.0), forces=((0, 0, 0), (0, 0, -10)))
    robot = robodyn.load("rp_arm")
    print(table_text(rows, robot.joint_names, [dof.effort_unit for dof in robot.dofs]))


if __name__ == "__main__":
    main()
