"""The example-robot-data zoo: robot names and where their URDF files are installed.

The ``example-robot-data`` package installs URDF files and meshes under
``<site-packages>/cmeel.prefix/share/example-robot-data/robots``. This module maps the zoo's
robot names (the names ``example_robot_data.load`` uses) to those files, so that robodyn
needs no Pinocchio-based loader. It does not import Pinocchio.
"""

from __future__ import annotations

import difflib
import sys
import sysconfig
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from robodyn.exceptions import MissingExtraError, UnknownRobotError, URDFError


@dataclass(frozen=True)
class ZooRobot:
    """One robot of the zoo.

    Attributes:
        name: Zoo name, e.g. ``"panda"``.
        relative_path: URDF path relative to the zoo's ``robots`` folder.
        floating_base: Whether the robot moves freely in space (legged, flying, humanoid).
    """

    name: str
    relative_path: str
    floating_base: bool


def _robots(floating: bool, table: dict[str, str]) -> list[ZooRobot]:
    return [ZooRobot(name, path, floating) for name, path in table.items()]


_FIXED = {
    "alex_nub_hands": "alex_description/urdf/alex_nub_hands.urdf",
    "alex_psyonic_hands": "alex_description/urdf/alex_psyonic_hands.urdf",
    "alex_sake_hands": "alex_description/urdf/alex_sake_hands.urdf",
    "allegro_left_hand": "allegro_hand_description/urdf/allegro_left_hand.urdf",
    "allegro_right_hand": "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "asr_twodof": "asr_twodof_description/urdf/TwoDofs.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
    "bravo7_gripper": "bravo7_description/urdf/bravo7_gripper.urdf",
    "bravo7_no_ee": "bravo7_description/urdf/bravo7_no_ee.urdf",
    "double_pendulum": "double_pendulum_description/urdf/double_pendulum.urdf",
    "double_pendulum_continuous": "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
    "double_pendulum_simple": "double_pendulum_description/urdf/double_pendulum_simple.urdf",
    "finger_edu": "finger_edu_description/robots/finger_edu.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "panda_collision": "panda_description/urdf/panda_collision.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "so101": "so_arm_description/urdf/so101.urdf",
    "talos_arm": "talos_data/robots/talos_left_arm.urdf",
    "tiago": "tiago_description/robots/tiago.urdf",
    "tiago_dual": "tiago_description/robots/tiago_dual.urdf",
    "tiago_no_hand": "tiago_description/robots/tiago_no_hand.urdf",
    "tiago_pro": "tiago_pro_description/robots/tiago_pro.urdf",
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur3_gripper": "ur_description/urdf/ur3_gripper.urdf",
    "ur3_limited": "ur_description/urdf/ur3_joint_limited_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur5_gripper": "ur_description/urdf/ur5_gripper.urdf",
    "ur5_limited": "ur_description/urdf/ur5_joint_limited_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "ur10_limited": "ur_description/urdf/ur10_joint_limited_robot.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "z1": "z1_description/urdf/z1.urdf",
}

_FLOATING = {
    "a1": "a1_description/urdf/a1.urdf",
    "alexander": "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_c": "anymal_c_simple_description/urdf/anymal.urdf",
    "anymal_kinova": "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "b1": "b1_description/urdf/b1.urdf",
    "b1_z1": "b1_description/urdf/b1-z1.urdf",
    "bluevolta_bravo7_gripper": "bluevolta_description/urdf/bluevolta_bravo7_gripper.urdf",
    "bluevolta_bravo7_no_ee": "bluevolta_description/urdf/bluevolta_bravo7_no_ee.urdf",
    "bolt": "bolt_description/robots/bolt.urdf",
    "borinot": "borinot_description/urdf/borinot_flying_arm_2.urdf",
    "centauro": "centauro_description/urdf/centauro.urdf",
    "falcon_bravo7_gripper": "falcon_description/urdf/falcon_bravo7_gripper.urdf",
    "falcon_bravo7_no_ee": "falcon_description/urdf/falcon_bravo7_no_ee.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "g1_with_hands": "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
    "go1": "go1_description/urdf/go1.urdf",
    "go2": "go2_description/urdf/go2.urdf",
    "hector": "hector_description/robots/quadrotor_base.urdf",
    "hextilt": "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    "human": "human_description/robots/human.urdf",
    "hyq": "hyq_description/robots/hyq_no_sensors.urdf",
    "icub": "icub_description/robots/icub.urdf",
    "icub_reduced": "icub_description/robots/icub_reduced.urdf",
    "iris": "iris_description/robots/iris_simple.urdf",
    "laikago": "laikago_description/urdf/laikago.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
    "quadruped": "quadruped_description/urdf/quadruped.urdf",
    "romeo": "romeo_description/urdf/romeo.urdf",
    "simple_humanoid": "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "simple_humanoid_classical": "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
    "solo8": "solo_description/robots/solo.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
    "talos_box": "talos_data/robots/talos_reduced_box.urdf",
    "talos_full": "talos_data/robots/talos_full_v2.urdf",
    "talos_full_box": "talos_data/robots/talos_full_v2_box.urdf",
}

ZOO: dict[str, ZooRobot] = {robot.name: robot for robot in _robots(False, _FIXED) + _robots(True, _FLOATING)}


@cache
def robots_dir() -> Path:
    """Folder holding the zoo's robot packages (``.../share/example-robot-data/robots``).

    Raises:
        MissingExtraError: If example-robot-data is not installed (``robodyn[zoo]``).
    """
    tail = Path("cmeel.prefix", "share", "example-robot-data", "robots")
    candidates = [Path(sysconfig.get_paths()["purelib"]) / tail]
    candidates += [Path(entry) / tail for entry in sys.path if entry]
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    raise MissingExtraError("example_robot_data", "zoo", "zoo robots")


def zoo_names() -> list[str]:
    """Names of the zoo robots whose URDF is installed, sorted."""
    return sorted(name for name, robot in ZOO.items() if (robots_dir() / robot.relative_path).is_file())


def zoo_robot(name: str) -> ZooRobot:
    """Look up a zoo robot by name.

    Args:
        name: The robot's name (``robodyn list`` prints them).

    Raises:
        UnknownRobotError: If the name is not in the zoo.
    """
    if name not in ZOO:
        raise UnknownRobotError(name, difflib.get_close_matches(name, list(ZOO), n=3))
    return ZOO[name]


def zoo_urdf_path(name: str) -> Path:
    """Absolute path of a zoo robot's URDF file.

    Args:
        name: The robot's name (``robodyn list`` prints them).
    """
    path = robots_dir() / zoo_robot(name).relative_path
    if not path.is_file():
        raise URDFError(name, f"the zoo robot's URDF {path} is not installed")
    return path


def package_dirs() -> list[Path]:
    """Folders under which ``package://example-robot-data/...`` mesh paths resolve."""
    return [robots_dir().parent.parent]
