"""PD and computed torque leave the joints no actuator drives without torque.

A planar walker's root joints (MJCF's ``rootx``, ``rootz``, ``rooty``: slide, slide,
hinge) carry the whole body; with them unactuated and no ground the walker is in free
fall (all but the x slider, which the world holds up), so its centre of mass must fall as
``−½ g t²`` times the falling share of the mass, and keep its horizontal place
whatever the legs do (the legs' torques are internal): a physical law the run must obey.
Negative control: with every joint driven, PD holds ``rootz`` up with the whole weight.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.experiment import run_simulation
from robodyn.sim.gains import joint_inertia
from robodyn.sim.underactuated import UnderactuatedComputedTorque, UnderactuatedPD, driven_dofs, driven_torques

WALKER = Path(__file__).parents[1] / "data" / "robots" / "planar_walker.urdf"
Q0 = [0.0, 0.0, 0.1, 0.3, -0.6]
TARGET = [0.0, 0.0, 0.0, 0.5, -1.0]  # the root's three values are not targets: nothing drives them
DURATION = 0.5


@pytest.fixture(scope="module")
def walker():
    """The walker with its root unactuated, as its file's actuators would say."""
    robot = robodyn.load(WALKER)
    robot.dofs = tuple(replace(dof, actuated=not dof.name.startswith("root")) for dof in robot.dofs)
    return robot


def _centre_of_mass(robot: robodyn.Robot, q: np.ndarray) -> np.ndarray:
    data = robot.model.createData()
    return pin.centerOfMass(robot.model, data, q).copy()


@pytest.mark.parametrize("controller", ["pd", "computed-torque"])
def test_the_unactuated_root_gets_no_torque_and_the_walker_falls_freely(walker, controller):
    trajectory, summary = run_simulation(
        walker, controller=controller, target=TARGET, q0=Q0, duration=DURATION, joint_friction=False, limits="ignore"
    )
    assert np.all(trajectory.tau[:, :3] == 0.0) and np.abs(trajectory.tau[:, 3:]).max() > 0.1
    start, end = _centre_of_mass(walker, trajectory.q[0]), _centre_of_mass(walker, trajectory.q[-1])
    # the world holds only the x slider's 10 g up (rootx slides along x): the rest falls at g
    falling = 1.0 - walker.link_masses["slider_x"] / walker.total_mass
    assert end[2] - start[2] == pytest.approx(-0.5 * 9.81 * DURATION**2 * falling, abs=1e-8)
    assert abs(end[0] - start[0]) < 1e-8
    assert summary.final_joint_error < (1e-6 if controller == "computed-torque" else 0.1)  # the driven joints only


def test_with_every_joint_driven_pd_holds_the_root_up(walker):
    trajectory, _ = run_simulation(
        walker, controller="pd", target=Q0, q0=Q0, duration=DURATION, joint_friction=False, limits="ignore",
        actuated=["rootx", "rootz", "rooty", "hip", "knee"],
    )  # fmt: skip
    assert np.abs(trajectory.tau[:, 1]).max() > 0.9 * walker.total_mass * 9.81  # the whole weight on rootz
    assert abs(trajectory.q[-1][1]) < 0.05  # held up: no free fall


def test_pd_holding_in_free_fall_needs_no_torque_where_gravitys_rows_would_give_some(walker):
    q = np.array(Q0)
    driven = driven_dofs(walker, None)
    holding = driven_torques(walker, q, np.zeros(5), np.zeros(2), driven)
    assert np.abs(holding).max() < 1e-9  # nothing to hold in free fall
    assert np.abs(walker.gravity(q)[3:]).max() > 1.0  # the rows of G hold a robot whose root is held


def test_the_driven_set_defaults_to_the_files_actuators_and_names_are_checked(walker):
    np.testing.assert_array_equal(driven_dofs(walker, None), [False, False, False, True, True])
    np.testing.assert_array_equal(driven_dofs(walker, ["knee"]), [False, False, False, False, True])
    with pytest.raises(InputError, match=r"^actuated must be distinct joint names"):
        driven_dofs(walker, ["ankle"])
    with pytest.raises(InputError, match=r"^actuated must be given only with the pd, computed-torque or lqr"):
        run_simulation(walker, controller="task-space", target=[0.1, 0.2], actuated=["hip"])
    # the driven joints' gains see the root give way: less inertia than M_jj
    free, held = joint_inertia(walker, np.array(Q0), driven_dofs(walker, None)), np.diag(walker.mass_matrix(np.array(Q0)))
    assert (free[3:] < held[3:]).all()


def test_the_laws_have_no_compiled_twin_so_both_engines_run_them_from_python(walker):
    from robodyn.compiled import has_twin

    law = UnderactuatedPD(walker, np.array(TARGET), 1.0, 1.0, driven=driven_dofs(walker, None))
    assert not has_twin(law) and not has_twin(UnderactuatedComputedTorque(walker, lambda t: (0, 0, 0), driven=law.driven))
