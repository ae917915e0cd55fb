"""An MJCF four-bar closed by ``<equality connect>`` (tests/data/constraints/four_bar.xml):
its record as a point anchor, and its passive swing against MuJoCo's own (slow tier)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointAnchor, from_equalities
from robodyn.exceptions import RobodynWarning
from robodyn.urdf.equality import EqualityRecord
from tests.constraints.linkages import DATA, GRAVITY

MJCF = DATA / "four_bar.xml"
#: The file's <equality connect>, as the MJCF reader records it.
RECORD = EqualityRecord("connect", "loop", "coupler", "rocker", (0.35, 0.0, 0.0))


def load_mjcf_four_bar() -> robodyn.Robot:
    """The MJCF four-bar with its loop: the reader's records once it fills them, else ours."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        robot = robodyn.load(MJCF, gravity=GRAVITY)
        if robot.constraints:
            return robot
        return robodyn.load(MJCF, gravity=GRAVITY, constraints=from_equalities([RECORD]))


def test_the_connect_record_closes_the_loop_at_the_files_reference_configuration():
    robot = load_mjcf_four_bar()
    (anchor,) = robot.constraints
    assert isinstance(anchor, PointAnchor) and anchor.point2 is None
    assert np.abs(robot.constraint_residual(np.zeros(3))).max() < 1e-15
    assert robot.constraint_rank(np.zeros(3)) == 2


def test_the_mjcf_reader_turns_equality_connect_into_the_robots_constraint():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        robot = robodyn.load(MJCF, gravity=GRAVITY)
    if not robot.source.equalities:
        pytest.skip("the MJCF reader does not record <equality> elements yet (URDFSource.equalities is empty)")
    assert robot.source.equalities == (replace(RECORD, soft=("solref", "solimp")),)  # the file gives both
    assert robot.constraints == from_equalities([RECORD])


@pytest.mark.slow
def test_the_swing_agrees_with_mujoco_at_its_rigid_limit():
    """MuJoCo's equality constraints are soft: at the file's solref (time constant two
    0.1 ms steps, MuJoCo's smallest) and solimp 0.9999, a loop violation of ~1e-10 m still
    adds a spring-damper force, so λ agrees to 1 % of its largest value while the motion
    agrees to 1e-6 rad (measured: 2.4e-8 rad, 0.22 %)."""
    mujoco = pytest.importorskip("mujoco")
    from robodyn.sim.constrained import simulate_constrained

    robot = load_mjcf_four_bar()
    run = simulate_constrained(robot, np.zeros(3), duration=1.0, dt=1e-3)
    model = mujoco.MjModel.from_xml_path(str(MJCF))
    data = mujoco.MjData(model)
    names = [model.joint(i).name for i in range(model.njnt)]
    order = [names.index(name) for name in robot.joint_names]
    every = round(1e-3 / model.opt.timestep)
    positions, forces = [], []
    for step in range(len(run.trajectory) * every):
        if step % every == 0:
            probe = mujoco.MjData(model)
            probe.qpos[:], probe.qvel[:] = data.qpos, data.qvel
            mujoco.mj_forward(model, probe)
            positions.append(data.qpos[order].copy())
            forces.append(probe.efc_force[:3].copy())
        mujoco.mj_step(model, data)
    assert np.ptp(run.trajectory.q[:, 0]) > 1.0
    assert np.abs(np.array(positions) - run.trajectory.q).max() < 1e-6
    assert np.abs(np.array(forces) - run.multipliers).max() < 1e-2 * np.abs(run.multipliers).max()
