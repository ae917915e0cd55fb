"""Contact from an MJCF file as the file says: its colliding geoms on its own plane
(``ground="file"``), a box at rest (a physical law) and against MuJoCo (its contacts
stiffened to their rigid limit, as in test_contact_mujoco.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robodyn
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import resolve_ground
from tests.conftest import ROOT

DATA = ROOT / "tests" / "data" / "mjcf"
DT = 1e-3


def _box_start(robot: robodyn.Robot) -> np.ndarray:
    q0 = robot.neutral_configuration()
    q0[:3] = (0.0, 0.0, 0.3)
    q0[3:7] = (0.0, 0.0, math.sin(math.radians(10)), math.cos(math.radians(10)))  # euler="0 0 20"
    return q0


def test_a_box_dropped_on_the_files_plane_rests_on_it_carrying_its_weight():
    """The plane is 0.1 m up, gravity 9.5 m/s² (both from the file): the box's centre
    rests 0.05 m (its half height) above the plane and the normal forces add to m g."""
    robot = robodyn.load(DATA / "contact_box.xml")
    ground = resolve_ground(robot, "file")
    run = simulate_contact(robot, ground=ground, duration=1.0, dt=DT, q0=_box_start(robot))
    assert abs(run.trajectory.q[-1, 2] - 0.15) < 1e-6
    assert abs(run.normal_forces[-1].sum() / (2.5 * 9.5) - 1) < 1e-6
    trajectory = robodyn.simulate(robot, _box_start(robot), np.zeros(6), 1.0, DT, ground="file")
    assert np.abs(trajectory.q[-1] - run.trajectory.q[-1]).max() < 1e-12


def _mujoco(path):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep, model.opt.cone = DT, mujoco.mjtCone.mjCONE_ELLIPTIC
    model.geom_solref[:] = (2 * DT, 1.0)
    model.geom_solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    return mujoco, model


def _run_mujoco(path, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's start (its qpos0, robodyn's order) and final configuration."""
    mujoco, model = _mujoco(path)
    data = mujoco.MjData(model)
    start = data.qpos.copy()
    for _ in range(round(duration / DT)):
        mujoco.mj_step(model, data)
    order = [0, 1, 2, 4, 5, 6, 3]  # w x y z → x y z w
    return start[order], data.qpos[order]


@pytest.mark.slow
def test_the_box_rests_at_mujocos_height():
    robot = robodyn.load(DATA / "contact_box.xml")
    start, theirs = _run_mujoco(DATA / "contact_box.xml", 1.0)
    run = simulate_contact(robot, ground=resolve_ground(robot, "file"), duration=1.0, dt=DT, q0=start)
    assert abs(run.trajectory.q[-1, 2] - theirs[2]) < 1e-4  # [m]: MuJoCo's soft contact sinks


@pytest.mark.slow
def test_a_four_legged_body_dropped_for_two_seconds_lands_where_mujoco_lands_it():
    """Capsule legs (MuJoCo's capsule–plane contacts are its two end spheres too), a
    tilted start, μ = 0.9 from the plane."""
    robot = robodyn.load(DATA / "contact_legs.xml")
    start, theirs = _run_mujoco(DATA / "contact_legs.xml", 2.0)
    run = simulate_contact(robot, ground=resolve_ground(robot, "file"), duration=2.0, dt=DT, q0=start)
    ours = run.trajectory.q[-1]
    assert np.abs(ours[:3] - theirs[:3]).max() < 2e-3  # [m]
    assert min(abs(ours[3:] @ theirs[3:]), 1.0) > math.cos(1e-2 / 2)  # within 0.01 rad
    assert abs(run.normal_forces[-1].sum() / (robot.total_mass * 9.81) - 1) < 1e-6
