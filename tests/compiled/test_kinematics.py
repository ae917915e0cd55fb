"""Compiled frame kinematics (position, rotation, Jacobian, J̇ q̇) against Pinocchio's."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.compiled import compile
from robodyn.exceptions import FrameError
from tests.compiled_helpers import relative_error, shared_cache
from tests.conftest import NONDEGENERATE_CASES, ROOT

#: The issue's bar for the frame kernels.
TOLERANCE = 1e-10
TWO_BRANCHES = ROOT / "tests" / "data" / "two_branches.urdf"


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


def pinocchio_frame(robot, frame: str, q: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """Position, rotation, LOCAL_WORLD_ALIGNED Jacobian and classical bias, from Pinocchio."""
    model, data, index = robot.model, robot.model.createData(), robot.frame_id(frame)
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, v, np.zeros(robot.nv))
    placement = pin.updateFramePlacement(model, data, index)
    jacobian = pin.getFrameJacobian(model, data, index, pin.LOCAL_WORLD_ALIGNED).reshape(6, robot.nv)
    bias = pin.getFrameClassicalAcceleration(model, data, index, pin.LOCAL_WORLD_ALIGNED).vector
    return {"position": placement.translation, "rotation": placement.rotation, "jacobian": jacobian, "bias": bias}


def errors(compiled, robot, frame: str, rng: np.random.Generator) -> dict[str, float]:
    """The largest relative error of each quantity over a few random states, one at a time."""
    worst = dict.fromkeys(("position", "rotation", "jacobian", "bias"), 0.0)
    q, v = robot.random_configuration(rng, 5), rng.normal(size=(5, robot.nv))
    for qi, vi in zip(q, v, strict=True):
        theirs = pinocchio_frame(robot, frame, qi, vi)
        ours = {
            "position": compiled.frame_position(qi, frame),
            "rotation": compiled.frame_rotation(qi, frame),
            "jacobian": compiled.frame_jacobian(qi, frame),
            "bias": compiled.frame_bias_acceleration(qi, vi, frame, angular=True),
        }
        for name in worst:  # relative to the result's scale, at least 1 (a zero bias is compared absolutely)
            scale = max(1.0, float(np.abs(theirs[name]).max()))
            worst[name] = max(worst[name], float(np.abs(ours[name] - theirs[name]).max()) / scale)
    return worst


SLOW = pytest.mark.slow
CASES = [
    # oblique non-unit axes, six-valued origins, a fixed joint mid-chain (its link), the base
    pytest.param(NONDEGENERATE_CASES["oblique"], ["end_effector", "bracket_link", "base"], id="oblique"),
    pytest.param((TWO_BRANCHES, {}), ["a_tip", "z_slider"], id="two_branches", marks=SLOW),  # a tree, a prismatic tip
    pytest.param(NONDEGENERATE_CASES["oblique"], ["j_extend", "j_tool"], id="oblique_joint_frames", marks=SLOW),
    pytest.param(NONDEGENERATE_CASES["mimic_tree"], ["hand", "finger"], id="mimic_tree", marks=SLOW),  # J = J_bodies S
    pytest.param(
        ("panda", {"lock": {"panda_finger_joint1": 0.0}}),
        ["panda_hand_tcp", "panda_link4", "panda_rightfinger"],
        id="panda_arm",
        marks=SLOW,
    ),  # fixed chains
]


@pytest.mark.parametrize(("case", "frames"), CASES)
def test_compiled_frame_kinematics_match_pinocchio(case, frames, rng):
    source, options = case
    robot = robodyn.load(source, **options)
    compiled = compile(robot)
    for frame in frames or [robot.end_effector]:
        worst = errors(compiled, robot, frame, rng)
        assert max(worst.values()) <= TOLERANCE, (frame, worst)


def test_compiled_frames_follow_the_robot_shape_rule_and_its_linear_bias(rng):
    robot = robodyn.load(*NONDEGENERATE_CASES["oblique"][:1])
    compiled, frame = compile(robot), "end_effector"
    q, v = robot.random_configuration(rng, 7), rng.normal(size=(7, robot.nv))
    assert compiled.frame_position(q, frame).shape == (7, 3)
    assert compiled.frame_jacobian(q, frame).shape == (7, 6, robot.nv)
    assert relative_error(compiled.frame_jacobian(q, frame), robot.frame_jacobian(q, frame)) <= TOLERANCE
    assert relative_error(compiled.frame_position(q.tolist()[2], frame), robot.frame_position(q[2], frame)) <= TOLERANCE
    bias = compiled.frame_bias_acceleration(q[0], v[0], frame)
    assert bias.shape == (3,)
    assert relative_error(bias, robot.frame_bias_acceleration(q[0], v[0], frame)) <= TOLERANCE


def test_the_bias_acceleration_is_the_second_derivative_of_the_position(rng):
    """Independent of Pinocchio: d²p/dt² along q(t) = q0 + t v equals J̇ v (central differences)."""
    robot = robodyn.load(*NONDEGENERATE_CASES["oblique"][:1])
    compiled, frame, h = compile(robot), "end_effector", 1e-4
    q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
    second = (compiled.frame_position(q + h * v, frame) - 2 * compiled.frame_position(q, frame)) + compiled.frame_position(
        q - h * v, frame
    )
    assert np.abs(second / h**2 - compiled.frame_bias_acceleration(q, v, frame)).max() < 1e-5


def test_negative_control_a_shifted_joint_origin_fails_the_comparison(rng, tmp_path):
    """One joint origin moved by 1e-6 m: the compiled frame must disagree (else nothing is checked)."""
    robot = robodyn.load("rp_arm")
    joint = robot.urdf.index('<joint name="joint2"')
    origin = robot.urdf.index('<origin xyz="', joint) + len('<origin xyz="')
    end = robot.urdf.index('"', origin)
    x, y, z = (float(value) for value in robot.urdf[origin:end].split())
    path = tmp_path / "shifted.urdf"
    path.write_text(robot.urdf[:origin] + f"{x + 1e-6!r} {y!r} {z!r}" + robot.urdf[end:])
    shifted = compile(robodyn.load(path))
    worst = errors(shifted, robot, robot.end_effector, rng)
    assert worst["position"] > TOLERANCE


def test_an_unknown_frame_is_refused_with_the_closest_names():
    compiled = compile(robodyn.load("rp_arm"))
    with pytest.raises(FrameError):
        compiled.frame_position(np.zeros(compiled.nq), "no_such_frame")
