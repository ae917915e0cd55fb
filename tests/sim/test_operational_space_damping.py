"""The OSC's damped task inertia where the damping binds and where it is slack.

``Λ = U diag(s / (s² + λ²)) Uᵀ`` with ``λ = damping · max(s)``: each damped eigenvalue is at
most ``1 / 2λ``, reached exactly where ``s = λ`` (the binding case: a direction as weak as
the damping), and within a relative ``(λ / s)²`` of the plain ``1 / s`` where ``s ≫ λ``
(slack). Checked on matrices built from chosen eigenvalues in a random 3-D basis.

The variable damping (:mod:`robodyn.sim.task_damping`): exactly off on an ordinary pose,
bounded torques from a stretched start (negative control: off, the run overflows), and the
compiled twin's rule the same as the Python law's.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import SimulationError
from robodyn.sim.operational_space import OperationalSpace, damped_task_inertia
from robodyn.sim.task_damping import total_damping, variable_damping


def built(values: list[float], seed: int = 39) -> tuple[np.ndarray, np.ndarray]:
    basis, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(len(values), len(values))))
    return basis @ np.diag(values) @ basis.T, basis


def test_the_damping_binds_exactly_where_a_direction_is_as_weak_as_it():
    damping, largest = 1e-2, 4.0
    weak = damping * largest  # s = λ: the damped value is its bound 1 / 2λ
    inverse, basis = built([weak, 0.5, largest])
    inertia = damped_task_inertia(inverse, damping)
    along = basis[:, 0] @ inertia @ basis[:, 0]
    assert abs(along - 1 / (2 * weak)) < 1e-12 * along
    assert np.linalg.eigvalsh(inertia)[-1] <= 1 / (2 * weak) * (1 + 1e-12)
    # Weaker still (s = λ / 10): below the bound, where the plain inverse is 10 / λ.
    inverse, basis = built([weak / 10, 0.5, largest])
    along = basis[:, 0] @ damped_task_inertia(inverse, damping) @ basis[:, 0]
    assert along < 1 / (2 * weak) and abs(along - (weak / 10) / ((weak / 10) ** 2 + weak**2)) < 1e-12 * along


def test_the_damping_is_slack_where_every_direction_is_strong():
    damping, values = 1e-3, [0.8, 1.5, 4.0]
    inverse, _ = built(values)
    plain = np.linalg.inv(inverse)
    damped = damped_task_inertia(inverse, damping)
    bound = (damping * max(values) / min(values)) ** 2  # relative change of the weakest direction
    assert np.abs(damped - plain).max() <= bound * np.abs(plain).max()
    assert np.abs(damped - plain).max() > 0.1 * bound * np.abs(plain).max() / max(values)  # it does act a little
    np.testing.assert_allclose(damped_task_inertia(inverse, 0.0), plain, rtol=1e-12, atol=1e-14)


# The variable damping of Nakamura and Chiaverini (robodyn.sim.task_damping): off away from
# singularities, on near them.
UR5_STRETCHED = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])  # elbow straight
UR5_ORDINARY = np.array([0.3, -1.2, 1.4, -1.5, -1.4, 0.2])  # the closed-loop-law tests' start


def test_the_variable_damping_is_zero_above_the_threshold_and_grows_smoothly_to_its_maximum():
    assert variable_damping(0.05, 0.05, 1e-2) == 0.0 and variable_damping(0.3, 0.05, 1e-2) == 0.0
    assert variable_damping(0.0, 0.05, 1e-2) == 1e-2
    assert variable_damping(0.03, 0.05, 1e-2) == pytest.approx(1e-2 * 0.8, rel=1e-15)  # √(1 − 0.6²)
    just_below = variable_damping(0.05 * (1 - 1e-12), 0.05, 1e-2)
    assert 0 < just_below < 1e-7  # continuous at the threshold
    assert total_damping(1e-8, 0.0) == 1e-8  # exactly the floor where it is off


def test_on_an_ordinary_pose_the_law_is_exactly_the_one_without_the_variable_damping():
    """The ur5 start of the closed-loop-law tests (σ about 0.18 of the chain's length, above
    the threshold): the default law's torque is bit for bit the one with the variable
    damping off, and within 1e-9 of the plain inverse ``(J M⁻¹ Jᵀ)⁻¹``."""
    robot = robodyn.load("ur5")
    v = np.array([0.2, -0.1, 0.3, 0.1, -0.2, 0.15])
    options = {"orientation": [0.1, 0.2, 0.3], "kp": 400.0, "kd": 30.0}
    default = OperationalSpace(robot, None, [0.3, 0.2, 0.4], **options)
    assert default.singular_value(UR5_ORDINARY) > 2 * default.singular_threshold
    off = OperationalSpace(robot, None, [0.3, 0.2, 0.4], singular_damping=0.0, **options)
    assert np.array_equal(default(0.0, UR5_ORDINARY, v), off(0.0, UR5_ORDINARY, v))
    plain = OperationalSpace(robot, None, [0.3, 0.2, 0.4], damping=0.0, singular_damping=0.0, **options)
    torque = plain(0.0, UR5_ORDINARY, v)
    assert np.abs(default(0.0, UR5_ORDINARY, v) - torque).max() <= 1e-9 * np.abs(torque).max()


def test_a_stretched_ur5_start_keeps_bounded_torques_by_default_and_overflows_without_the_variable_damping():
    """Position task from the elbow-straight pose (the frame's position Jacobian has rank 1
    there): the default law's torques stay finite and under 500 N m over 0.3 s (over 3 s
    the peak is 286 N m and the target is reached; the same task from a bent start,
    stretched + 0.4 rad, outside the damped region, peaks at 221 N m); with the variable
    damping off the run overflows within 10 ms."""
    robot = robodyn.load("ur5")
    law = OperationalSpace(robot, None, [0.3, 0.2, 0.4])
    assert law.singular_value(UR5_STRETCHED) < 1e-9
    with pytest.warns(robodyn.RobodynWarning, match="damped there"):
        run = robodyn.simulate(robot, UR5_STRETCHED, np.zeros(6), 0.3, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    assert np.isfinite(run.tau).all() and np.abs(run.tau).max() < 500.0
    assert law.singular_value(run.q[-1]) > law.singular_threshold  # it left the singularity
    undamped = OperationalSpace(robot, None, [0.3, 0.2, 0.4], singular_damping=0.0)
    with pytest.warns(robodyn.RobodynWarning, match="without bound"), pytest.raises(SimulationError, match="overflow"):
        robodyn.simulate(robot, UR5_STRETCHED, np.zeros(6), 0.3, 1e-3, controller=undamped, limits="ignore", engine="pinocchio")


@pytest.mark.slow  # compiles the RP arm (5 s in a fresh cache)
def test_the_compiled_twin_damps_as_the_python_law_inside_the_damped_region():
    """The RP arm with its slider pulled back to the first joint's axis (r = −0.86 m: σ is
    below the threshold): the twin's run within 1e-9 of the Python law's; negative control:
    the twin with the variable damping off departs."""
    from robodyn.compiled import compile
    from robodyn.compiled.simulation import compiled_controller, simulate_compiled
    from tests.compiled_helpers import shared_cache

    robot = robodyn.load("rp_arm")
    law = OperationalSpace(robot, None, [0.7, 0.0, 0.7], kp=60.0, kd=14.0)
    q0 = np.array([0.3, -0.86])
    assert 0 < law.singular_value(q0) < law.singular_threshold
    with pytest.warns(robodyn.RobodynWarning, match="near a singularity"):
        python = robodyn.simulate(
            robot, q0, np.zeros(2), 0.2, 1e-3, controller=law, limits="ignore", engine="pinocchio", joint_friction=False
        )
    with shared_cache():
        twin = compiled_controller(law)
        compiled = simulate_compiled(compile(robot), q0, np.zeros(2), 0.2, 1e-3, controller=twin, joint_friction=False)
        plain = simulate_compiled(
            compile(robot), q0, np.zeros(2), 0.2, 1e-3, controller=dataclasses.replace(twin, singular_damping=0.0),
            joint_friction=False,
        )  # fmt: skip
    scale = max(1.0, float(np.abs(python.tau).max()))
    assert np.abs(compiled.q - python.q).max() <= 1e-9 and np.abs(compiled.tau - python.tau).max() <= 1e-9 * scale
    assert np.abs(plain.tau - python.tau).max() > 1e-3 * scale


#: dm_control's reacher as its suite writes it (two capsules in the horizontal plane, light
#: damping): stretched at q = 0, the task's second direction vanishes.
REACHER = """<mujoco><default><joint type="hinge" axis="0 0 1" damping="0.01"/></default><worldbody>
<body name="arm" pos="0 0 .01"><geom type="capsule" fromto="0 0 0 0.12 0 0" size=".01"/><joint name="shoulder"/>
  <body name="hand" pos=".12 0 0"><geom type="capsule" fromto="0 0 0 0.1 0 0" size=".01"/>
    <joint name="wrist" limited="true" range="-160 160"/>
    <body name="finger" pos=".12 0 0"><geom type="sphere" size=".01"/></body>
  </body>
</body></worldbody></mujoco>"""


def test_a_stretched_planar_reacher_moves_to_its_target_with_bounded_torques_and_overflows_without_the_variable_damping(tmp_path):
    """The reacher's planar task (rank 2: its normal is no singularity) from q = 0: peak
    torque 0.15 N m, the finger within 1 cm of the target after 0.5 s (0.13 m away at the start);
    with the variable damping off,
    the run overflows within 10 ms (the issue's "C v + G overflowed")."""
    path = tmp_path / "reacher.xml"
    path.write_text(REACHER)
    robot = robodyn.load(path)
    target = [0.1, 0.1, 0.01]
    law = OperationalSpace(robot, "finger", target, compensate_damping=True)
    assert law.singular_value(np.zeros(2)) < 1e-9 and law.singular_value(np.array([0.3, 1.0])) > law.singular_threshold
    with pytest.warns(robodyn.RobodynWarning, match="damped there"):
        run = robodyn.simulate(robot, np.zeros(2), np.zeros(2), 0.5, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    assert np.isfinite(run.tau).all() and np.abs(run.tau).max() < 0.5
    assert np.linalg.norm(robot.frame_position(run.q[-1], "finger") - target) < 0.01
    undamped = OperationalSpace(robot, "finger", target, compensate_damping=True, singular_damping=0.0)
    with pytest.warns(robodyn.RobodynWarning, match="without bound"), pytest.raises(SimulationError, match="overflow"):
        robodyn.simulate(robot, np.zeros(2), np.zeros(2), 0.05, 1e-3, controller=undamped, limits="ignore", engine="pinocchio")
