"""Symbolic kinematics of a frame two fixed joints past its body, each a rotation then an
offset (steps that do not commute), against Pinocchio's frame placement.

The robot is 3-D: a revolute about an oblique non-unit axis, a fixed elbow, a revolute
about a tilted axis (two moving joints keep the derivation to seconds); then ``flange`` (fixed: rpy and xyz all non-zero) and ``tool`` (fixed again)
past the last body. Composing the fixed steps in the wrong order, or adding an offset
without the rotation before it, moves the tool frame by centimetres.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import sympy as sp

import robodyn
from robodyn.equations.kinematics import derive_kinematics, render_kinematics

_BOX = '<inertial><origin xyz="{c}" rpy="0.2 -0.1 0.3"/><mass value="{m}"/><inertia ixx="0.02" iyy="0.025" izz="0.015" ixy="0.001" ixz="-0.002" iyz="0.001"/></inertial>'

ARM = f"""<robot name="fixed_chain_arm"><link name="base"/>
<link name="l1">{_BOX.format(c="0.02 0.01 0.1", m=1.2)}</link>
<link name="l2">{_BOX.format(c="0.1 -0.02 0.03", m=0.9)}</link>
<link name="l3">{_BOX.format(c="0.03 0.05 -0.02", m=0.6)}</link>
<link name="flange_link"/><link name="tool_link"/>
<joint name="yaw" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0.05 -0.03 0.2" rpy="0.1 0.2 -0.3"/>
  <axis xyz="0 3 4"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
<joint name="elbow" type="fixed"><parent link="l1"/><child link="l2"/><origin xyz="0.1 0.02 0.3" rpy="-0.4 0.3 0.2"/></joint>
<joint name="wrist" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.25 -0.05 0.04" rpy="0.5 -0.2 0.7"/>
  <axis xyz="0.2 1 -0.3"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
<joint name="flange" type="fixed"><parent link="l3"/><child link="flange_link"/><origin xyz="0.12 0.07 -0.05" rpy="1.1 -0.6 0.4"/></joint>
<joint name="tool" type="fixed"><parent link="flange_link"/><child link="tool_link"/><origin xyz="0.03 -0.15 0.2" rpy="-0.7 0.9 1.3"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def derived():
    kinematics = derive_kinematics(ARM, "tool_link")
    namespace: dict = {}
    exec(render_kinematics(kinematics, "python"), namespace)
    rotation = sp.lambdify(kinematics.q, kinematics.rotation, "numpy")
    return kinematics, namespace, rotation


def test_a_frame_two_fixed_joints_past_its_body_is_pinocchios_placement(derived, rng):
    kinematics, module, rotation = derived
    robot = robodyn.load(ARM)
    assert list(kinematics.joint_names) == list(robot.joint_names)
    model = robot.model
    data = model.createData()
    frame = model.getFrameId("tool_link")
    for q in robot.random_configuration(rng, 6):
        pin.framesForwardKinematics(model, data, q)
        placement = data.oMf[frame]
        assert np.abs(module["frame_position"](q) - placement.translation).max() < 1e-12
        assert np.abs(np.array(rotation(*q), dtype=float) - placement.rotation).max() < 1e-12
        jacobian = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        assert np.abs(module["frame_jacobian"](q) - jacobian).max() < 1e-12


def test_the_fixed_steps_in_the_other_order_are_told_apart(derived, rng):
    """Negative control: the tool frame with the two fixed steps composed offset-first
    (translation, then rotation) is somewhere else, by more than the test's tolerance."""
    _, module, _ = derived
    robot = robodyn.load(ARM)
    q = robot.random_configuration(rng, 1)[0]
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    body = data.oMf[model.getFrameId("l3")]
    steps = [pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)), np.array(xyz)) for rpy, xyz in
             (((1.1, -0.6, 0.4), (0.12, 0.07, -0.05)), ((-0.7, 0.9, 1.3), (0.03, -0.15, 0.2)))]  # fmt: skip
    right = body * steps[0] * steps[1]
    assert np.abs(module["frame_position"](q) - right.translation).max() < 1e-12
    swapped = [pin.SE3(step.rotation, np.zeros(3)) * pin.SE3(np.eye(3), step.translation) for step in steps]
    wrong = body * swapped[0] * swapped[1]
    assert np.abs(wrong.translation - right.translation).max() > 1e-2
    reversed_order = body * steps[1] * steps[0]
    assert np.abs(reversed_order.translation - right.translation).max() > 1e-2
