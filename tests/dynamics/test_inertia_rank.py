"""Joints whose motions together move no inertia (point masses turned about the line through
them): named at load time, in the simulator's refusal, and checked against Pinocchio's own
CRBA on a model it builds from the same file."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.dynamics.inertia_rank import inertialess_joints
from robodyn.exceptions import RobodynWarning, SingularMassMatrixError
from robodyn.urdf.zoo import zoo_urdf_path

# two revolute axes through one point (x, then y), a point mass behind them at `point`:
# on the line (1, 1, 0) the combined rotation about it moves nothing
NECK = """<robot name="neck"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0"
iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<joint name="roll" type="revolute"><parent link="base"/><child link="ring"/><axis xyz="1 0 0"/>
<limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
<link name="ring"><inertial><mass value="0.1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
<joint name="yaw" type="revolute"><parent link="ring"/><child link="head"/><axis xyz="0 1 0"/>
<limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
<link name="head"><inertial><origin xyz="{point}"/><mass value="1.3"/>
<inertia ixx="{moment}" ixy="0" ixz="0" iyy="{moment}" iyz="0" izz="{moment}"/></inertial></link></robot>"""


def loaded(text: str) -> tuple[robodyn.Robot, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RobodynWarning)
        robot = robodyn.load(text, gravity=(0.3, -0.2, -9.7))
    return robot, [str(w.message) for w in caught if "no inertia" in str(w.message)]


def pinocchio_null_joints(model: pin.Model, q: np.ndarray) -> set[str]:
    """The joints in the null space of Pinocchio's own CRBA (the independent check)."""
    mass = pin.crba(model, model.createData(), q)
    eigenvalues, vectors = np.linalg.eigh(np.triu(mass) + np.triu(mass, 1).T)
    null = vectors[:, eigenvalues <= 1e-12 * eigenvalues[-1]]
    return {
        model.names[j]
        for j in range(1, model.njoints)
        if np.linalg.norm(null[model.joints[j].idx_v : model.joints[j].idx_v + model.joints[j].nv]) > 0.1
    }


def test_point_masses_turned_about_their_line_are_named_at_load_and_in_the_simulators_refusal():
    robot, lines = loaded(NECK.format(point="0.3 0.3 0", moment="0"))
    (line,) = lines
    assert "'roll', 'yaw' together move no inertia at the neutral configuration" in line
    assert pinocchio_null_joints(pin.buildModelFromXML(NECK.format(point="0.3 0.3 0", moment="0")), np.zeros(2)) == {
        "roll",
        "yaw",
    }
    with pytest.raises(SingularMassMatrixError) as raised, warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)  # the step-size warning: the same stiffness
        robodyn.simulate(robot, np.zeros(2), np.zeros(2), duration=0.01, dt=1e-3)
    assert raised.value.joints == ["roll", "yaw"] and "no inertia" in str(raised.value)


@pytest.mark.parametrize(("point", "moment"), [("0.3 0.3 0.1", "0"), ("0.3 0.3 0", "1e-4")])
def test_a_point_mass_off_the_line_or_a_body_with_inertia_is_not_named(point, moment):
    robot, lines = loaded(NECK.format(point=point, moment=moment))
    assert lines == [] and inertialess_joints(robot, np.zeros(2)) == []


def test_icubs_head_is_a_point_mass_that_pinocchios_own_crba_finds_singular_too():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RobodynWarning)
        robot = robodyn.load("icub")
    (line,) = [str(w.message) for w in caught if "no inertia" in str(w.message)]
    assert "'neck_roll', 'neck_yaw'" in line
    model = pin.buildModelFromUrdf(str(zoo_urdf_path("icub")), pin.JointModelFreeFlyer())
    assert pinocchio_null_joints(model, pin.neutral(model)) == {"neck_roll", "neck_yaw"}
    assert inertialess_joints(robot, robot.random_configuration(np.random.default_rng(2))) == []  # only there


# The null space is judged relative to M's largest eigenvalue: the same joints named for a robot
# a million times lighter or heavier, and beside a heavy slider that carries it.
INERTIA = '<inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/>'
LIMIT = '<limit lower="-1" upper="1" effort="10" velocity="5"/>'


def neck(scale: float, moment: float, slider: float | None = None) -> str:
    """Two revolute axes through one point carrying a point mass on the line (1, 1, 0) (a
    body of inertia ``moment`` there when > 0), masses times ``scale``; behind a prismatic
    slider of mass ``slider`` when given."""
    base = f'<link name="base"><inertial><mass value="{scale}"/>{INERTIA.format(i=0.01 * scale)}</inertial></link>'
    parent = "base"
    text = base
    if slider is not None:
        text += (
            f'<joint name="lift" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="0 0 1"/>{LIMIT}</joint>'
        )
        text += f'<link name="carriage"><inertial><mass value="{slider}"/>{INERTIA.format(i=slider)}</inertial></link>'
        parent = "carriage"
    text += f'<joint name="roll" type="revolute"><parent link="{parent}"/><child link="ring"/><axis xyz="1 0 0"/>{LIMIT}</joint>'
    text += f'<link name="ring"><inertial><mass value="{0.1 * scale}"/>{INERTIA.format(i=0)}</inertial></link>'
    text += f'<joint name="yaw" type="revolute"><parent link="ring"/><child link="head"/><axis xyz="0 1 0"/>{LIMIT}</joint>'
    head = f'<origin xyz="0.3 0.3 0"/><mass value="{1.3 * scale}"/>{INERTIA.format(i=moment * scale)}'
    return f'<robot name="neck">{text}<link name="head"><inertial>{head}</inertial></link></robot>'


def named(text: str) -> list[str]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)  # the load-time line: tested elsewhere
        robot = robodyn.load(text)
    return inertialess_joints(robot, robot.neutral_configuration())


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_the_same_joints_are_named_for_a_robot_lighter_or_heavier_by_any_factor(scale):
    assert named(neck(scale, 0.0)) == ["roll", "yaw"]
    assert named(neck(scale, 1e-4)) == []


def test_a_heavy_slider_carrying_the_neck_leaves_its_null_space_to_the_neck():
    assert named(neck(1.0, 0.0, slider=1e6)) == ["roll", "yaw"]
    assert named(neck(1.0, 1e-4, slider=1e6)) == []
    # a head of inertia 1e-8 kg m²: 1e-14 of the slider's 1e6 kg, below the tolerance of the
    # largest eigenvalue (not of the neck's own, 0.23): no inertia, as the simulator judges it
    assert named(neck(1.0, 1e-8, slider=1e6)) == ["roll", "yaw"]
    assert named(neck(1.0, 1e-8)) == []
