"""Issue 42, hybrid force/motion control: the RP arm's tip pressing the wall ``x = 0.8``
with 10 N while sliding up and down, and the panda's hand wiping a table with 5 N along a
circle, both simulated with the contact as a frictionless constraint (its ``λ`` is the
measured normal force). Laws: the force equals the command, the motion error obeys
``ë + Kd ė + Kp e = 0`` (its exact solution beside it), the commanded force does no work
along the motion; the negative control drops the dynamic decoupling."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.linalg import expm

import robodyn
from robodyn.constraints import PointContact
from robodyn.exceptions import InputError
from robodyn.sim.constrained import simulate_constrained
from robodyn.sim.force_control import HybridForceMotion, circle

WALL_X, START_Z, AMPLITUDE, RATE, OFFSET = 0.8, 0.1, 0.1, np.pi, 0.03
KP, KD, FORCE = 100.0, 20.0, 10.0


def wall_reference(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Up and down the wall, starting ``OFFSET`` above the tip and moving (e₀, ė₀ ≠ 0)."""
    s, c = np.sin(RATE * t), np.cos(RATE * t)
    return (
        np.array([WALL_X, 0.0, START_Z + OFFSET + AMPLITUDE * s]),
        np.array([0.0, 0.0, AMPLITUDE * RATE * c]),
        np.array([0.0, 0.0, -AMPLITUDE * RATE**2 * s]),
    )


@cache
def on_the_wall(decoupled: bool):
    robot = robodyn.load("rp_arm")
    wall = PointContact("end_effector", normal=(-1, 0, 0), friction=0, plane_point=(WALL_X, 0, 0))
    q0 = np.array([np.arctan2(START_Z, WALL_X), np.hypot(WALL_X, START_Z) - 0.9])  # the tip on the wall, at rest
    control = HybridForceMotion(robot, None, (-1, 0, 0), FORCE, wall_reference, kp=KP, kd=KD, decoupled=decoupled)
    return control, simulate_constrained(robot, q0, constraints=[wall], duration=0.8, dt=4e-3, tau=control)


def law(times: np.ndarray) -> np.ndarray:
    """The solution of ``ë + Kd ė + Kp e = 0`` from ``e₀ = OFFSET``, ``ė₀ = A ω`` (the tip at rest)."""
    system = np.array([[0.0, 1.0], [-KP, -KD]])
    return np.array([(expm(system * t) @ [OFFSET, AMPLITUDE * RATE])[0] for t in times])


def motion_errors(control: HybridForceMotion, trajectory) -> np.ndarray:
    return np.array([control.motion_error(t, q, v)[0] for t, q, v in zip(trajectory.t, trajectory.q, trajectory.v, strict=True)])


def test_the_wall_force_is_the_command_and_the_motion_obeys_its_closed_loop_law():
    control, run = on_the_wall(decoupled=True)
    normal_force = run.multipliers[:, 0]
    assert normal_force.min() > 0  # the wall pushes: a unilateral contact would hold
    assert np.abs(normal_force - FORCE).max() <= 1e-6 * FORCE
    errors = motion_errors(control, run.trajectory)
    np.testing.assert_allclose(errors[:, [0, 1]], 0.0, atol=1e-15)  # along the wall: z only
    assert np.abs(errors[:, 2] - law(run.trajectory.t)).max() <= 1e-3 * OFFSET
    assert run.residual.max() <= 1e-12


def test_the_commanded_force_does_no_work_along_the_motion():
    control, run = on_the_wall(decoupled=True)
    np.testing.assert_allclose(control.motion_selection @ control.force_command, 0.0, atol=1e-15)
    np.testing.assert_allclose(control.force_selection @ control.force_command, control.force_command, atol=1e-15)
    robot = control.model
    velocity = np.einsum("nij,nj->ni", robot.frame_jacobian(run.trajectory.q, "end_effector")[:, :3], run.trajectory.v)
    power = velocity @ control.force_command  # [W]
    work = float(np.sum(np.abs(power)) * 4e-3)
    travelled = float(np.sum(np.linalg.norm(velocity, axis=1)) * 4e-3)
    assert travelled > 0.1 and work <= 1e-9 * FORCE * travelled


def test_without_dynamic_decoupling_the_force_transient_couples_into_the_motion():
    """Negative control: the same gains with a scalar task mass instead of ``Λ``."""
    control, run = on_the_wall(decoupled=False)
    errors = motion_errors(control, run.trajectory)
    assert np.abs(errors[:, 2] - law(run.trajectory.t)).max() > 1e-2 * OFFSET
    assert np.abs(run.multipliers[:, 0] - FORCE).max() > 1e-2 * FORCE


@pytest.mark.slow
def test_the_panda_wipes_a_table_with_five_newtons_along_a_circle():
    robot = robodyn.load("panda")
    q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785, 0.02])
    start = robot.frame_position(q0, "panda_hand_tcp")
    table = PointContact("panda_hand_tcp", normal=(0, 0, 1), friction=0, plane_point=start)
    radius, period = 0.05, 2.0
    center = start - (circle(np.zeros(3), radius, (0, 0, 1), period)(0.0)[0])
    path = circle(center, radius, (0, 0, 1), period)
    control = HybridForceMotion(robot, "panda_hand_tcp", (0, 0, 1), 5.0, path, posture=q0)
    run = simulate_constrained(robot, q0, constraints=[table], duration=1.5, dt=2e-3, tau=control)
    late = run.trajectory.t >= 0.5
    assert np.abs(run.multipliers[late, 0] - 5.0).max() <= 0.01 * 5.0
    assert run.multipliers[:, 0].min() > 0
    hand = robot.frame_position(run.trajectory.q, "panda_hand_tcp")
    off_circle = np.abs(np.linalg.norm(hand[late, :2] - center[:2], axis=1) - radius)
    assert off_circle.max() <= 1e-3
    assert np.abs(hand[:, 2] - start[2]).max() <= 1e-9  # on the table


def test_bad_normals_forces_and_motions_are_refused():
    robot = robodyn.load("rp_arm")
    with pytest.raises(InputError, match="normal"):
        HybridForceMotion(robot, None, (0, 0, 0), 1.0, np.zeros(3))
    with pytest.raises(InputError, match="force"):
        HybridForceMotion(robot, None, (1, 0, 0), -1.0, np.zeros(3))
    with pytest.raises(InputError, match="motion"):
        HybridForceMotion(robot, None, (1, 0, 0), 1.0, np.array([0.0, np.nan, 0.0]))
    with pytest.raises(InputError, match="radius"):
        circle(np.zeros(3), 0.0, (0, 0, 1), 1.0)


@pytest.mark.parametrize(("field", "value"), [("normal", "down"), ("force", "ten"), ("motion", "up"), ("kp", np.inf)])
def test_hostile_values_are_refused_in_one_sentence(field, value):
    robot = robodyn.load("rp_arm")
    arguments = {"normal": (1, 0, 0), "force": 1.0, "motion": np.zeros(3)}
    options = {}
    if field in arguments:
        arguments[field] = value
    else:
        options[field] = value
    with pytest.raises(InputError, match=field):
        HybridForceMotion(robot, None, arguments["normal"], arguments["force"], arguments["motion"], **options)


@pytest.mark.parametrize("compensate", [True, False], ids=["compensated", "negative_control_rigid_law"])
def test_on_damped_joints_the_sliding_force_is_the_command_only_when_the_law_compensates(compensate):
    """The RP arm's joints damped (``b`` 3 N m s/rad, the plant's torque ``τ − b v``),
    gravity tilted: compensated, the wall force is the command at every instant and the
    motion keeps its law; the rigid-body law's force is off by the sliding's damping,
    ``nᵀ J M⁻¹ b v / nᵀ Λ⁻¹ n`` (computed here from the run's states, not by the law)."""
    from robodyn.urdf.models.rp_arm import rp_arm_urdf

    robot = robodyn.load(rp_arm_urdf().replace("</joint>", '<dynamics damping="3.0"/></joint>', 2), gravity=(0.4, 0, -9.7))
    wall = PointContact("end_effector", normal=(-1, 0, 0), friction=0, plane_point=(WALL_X, 0, 0))
    q0 = np.array([np.arctan2(START_Z, WALL_X), np.hypot(WALL_X, START_Z) - 0.9])
    control = HybridForceMotion(robot, None, (-1, 0, 0), FORCE, wall_reference, kp=KP, kd=KD, compensate_damping=compensate)
    damping = robot.joint_damping

    def plant(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return control(t, q, v) - damping * v

    run = simulate_constrained(robot, q0, constraints=[wall], duration=0.4, dt=4e-3, tau=plant)
    trajectory, normal = run.trajectory, np.array([-1.0, 0.0, 0.0])
    bias = []
    for q, v in zip(trajectory.q, trajectory.v, strict=True):
        jacobian, mass = robot.frame_jacobian(q, "end_effector")[:3], robot.mass_matrix(q)
        bias.append(
            normal
            @ jacobian
            @ np.linalg.solve(mass, damping * v)
            / (normal @ jacobian @ np.linalg.solve(mass, jacobian.T) @ normal)
        )
    error = run.multipliers[:, 0] - FORCE
    assert np.abs(bias).max() > 1e-2 * FORCE  # the sliding's damping is large enough to show
    if compensate:
        assert np.abs(error).max() <= 1e-6 * FORCE
        assert np.abs(motion_errors(control, trajectory)[:, 2] - law(trajectory.t)).max() <= 1e-3 * OFFSET
    else:
        np.testing.assert_allclose(error, bias, atol=1e-9 * FORCE)
