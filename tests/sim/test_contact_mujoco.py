"""Contact simulation against MuJoCo (its contacts stiffened to their rigid limit): solo12 standing, a box sliding."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import ContactPoint, Ground

mujoco = pytest.importorskip("mujoco")

DATA = Path(__file__).parents[1] / "data" / "contact"
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
RADIUS = 1e-4  # MuJoCo's contacts are between geoms: the feet are spheres this small
DT = 1e-3


def _mujoco_model(urdf: str, spheres: dict[str, float], friction: float, tilt: float = 0.0):
    """MuJoCo's model of a URDF on a free base: no visuals or collisions but ``spheres``
    (body: radius), a plane tilted about y, elliptic cones, contacts at their rigid limit
    (``solref`` two steps, critically damped; ``solimp`` 0.99–0.9999)."""
    root = ET.fromstring(urdf)
    for link in root.findall("link"):
        for kind in ("visual", "collision"):
            for element in link.findall(kind):
                link.remove(element)
    options = ET.SubElement(root, "mujoco")
    ET.SubElement(options, "compiler", fusestatic="false", discardvisual="true", balanceinertia="false")
    spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    spec.worldbody.first_body().add_freejoint()
    for body, radius in spheres.items():
        spec.body(body).add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[radius, 0, 0], condim=3, friction=[friction, 0, 0])
    spec.worldbody.add_geom(
        type=mujoco.mjtGeom.mjGEOM_PLANE, size=[50, 50, 0.1], condim=3, friction=[friction, 0, 0],
        quat=[math.cos(tilt / 2), 0, math.sin(tilt / 2), 0],
    )  # fmt: skip
    spec.option.timestep, spec.option.cone = DT, mujoco.mjtCone.mjCONE_ELLIPTIC
    model = spec.compile()
    model.geom_solref[:] = (2 * DT, 1.0)
    model.geom_solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    return model


def _to_mujoco(q: np.ndarray) -> np.ndarray:
    return np.concatenate([q[:3], q[6:7], q[3:6], q[7:]])  # quaternion x y z w → w x y z


def _normal_sum(model, data) -> float:
    force, total = np.zeros(6), 0.0
    for index in range(data.ncon):
        mujoco.mj_contactForce(model, data, index, force)
        total += force[0]
    return total


@pytest.mark.slow
def test_solo12_dropped_on_its_feet_rests_where_mujoco_rests_it():
    robot = robodyn.load("solo12")
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), RADIUS) for foot in FEET)
    q0 = robot.neutral_configuration()
    q0[2] = -contact_kinematics(robot, q0, Ground(), points)[0].min() + 0.05
    target = q0[7:].copy()

    def hold(t, q, v):
        tau = np.zeros(robot.nv)
        tau[6:] = 5.0 * (target - q[7:]) - 0.1 * v[6:]
        return tau

    model = _mujoco_model(robot.urdf, {foot: RADIUS for foot in FEET}, 0.8)
    data = mujoco.MjData(model)
    data.qpos[:] = _to_mujoco(q0)
    for _ in range(1000):
        data.qfrc_applied[6:] = hold(0.0, np.r_[np.zeros(7), data.qpos[7:]], np.r_[np.zeros(6), data.qvel[6:]])[6:]
        mujoco.mj_step(model, data)
    run = simulate_contact(robot, ground=Ground(friction=0.8), contacts=points, controller=hold, duration=1.0, dt=DT, q0=q0)
    final = _to_mujoco(run.trajectory.q[-1])
    weight = robot.total_mass * 9.81
    assert abs(final[2] - data.qpos[2]) < 1e-4  # MuJoCo's soft contact sinks 4.5e-5 m
    assert np.abs(final[7:] - data.qpos[7:]).max() < 2e-3  # [rad]: 6.6e-4 measured
    assert abs(run.normal_forces[-1].sum() / weight - 1) < 1e-6
    assert abs(_normal_sum(model, data) / weight - 1) < 1e-4


@pytest.mark.slow
@pytest.mark.parametrize("degrees", [35.0, 15.0])
def test_a_box_on_a_slope_moves_as_mujocos(degrees):
    """A box on a plane tilted by 35° (slides: 72.6 mm in 0.3 s, MuJoCo 72.0 mm) and by 15°
    (sticks; MuJoCo creeps 4.5 µm), μ = 0.5, 1 ms steps."""
    box = robodyn.load(DATA / "box.urdf", floating_base=True)
    theta, friction = math.radians(degrees), 0.5
    ground = Ground.tilted(theta, friction=friction)
    q0 = box.neutral_configuration()
    q0[:3] = 0.05 * np.array(ground.normal)
    q0[3:7] = (0.0, math.sin(theta / 2), 0.0, math.cos(theta / 2))
    run = simulate_contact(box, ground=ground, duration=0.3, dt=DT, q0=q0)
    model = _box_model(theta, friction)
    data = mujoco.MjData(model)
    data.qpos[:] = _to_mujoco(q0)
    for _ in range(300):
        mujoco.mj_step(model, data)
    down = np.array([math.cos(theta), 0.0, -math.sin(theta)])
    ours, theirs = run.trajectory.q[-1, :3] @ down, data.qpos[:3] @ down
    assert abs(ours - theirs) < 0.02 * abs(ours) + 1e-5  # [m]: within 2 % of the slide


def _box_model(theta: float, friction: float):
    """The box as MuJoCo's own box geom on the tilted plane."""
    spec = mujoco.MjSpec()
    spec.option.timestep, spec.option.cone = DT, mujoco.mjtCone.mjCONE_ELLIPTIC
    body = spec.worldbody.add_body(name="box")
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.15, 0.1, 0.05], mass=2.5, condim=3, friction=[friction, 0, 0])
    spec.worldbody.add_geom(
        type=mujoco.mjtGeom.mjGEOM_PLANE, size=[50, 50, 0.1], condim=3, friction=[friction, 0, 0],
        quat=[math.cos(theta / 2), 0, math.sin(theta / 2), 0],
    )  # fmt: skip
    model = spec.compile()
    model.geom_solref[:] = (2 * DT, 1.0)
    model.geom_solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    return model
