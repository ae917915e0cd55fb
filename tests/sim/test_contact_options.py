"""Issue 39, contacts crossed with a gravity that is not along −z (the ground's code never
reads the robot's gravity: the solver sees it only through the dynamics). A box on flat
ground under gravity tilted towards an azimuth of 30° sticks below the friction angle
carrying ``−m g`` (its tangential part too), slides above it with ``|g| (sin θ − μ cos θ)``
along the gravity's horizontal direction, and on a frictionless plane normal to gravity
stays put. The sliding case is the sticking case's negative control (same code, only the
angle differs, and the box moves)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import Ground

BOX = Path(__file__).resolve().parent.parent / "data" / "contact" / "box.urdf"
MASS, HALF_HEIGHT, G = 2.5, 0.05, 9.81
AZIMUTH = math.radians(30.0)


def tilted_gravity(theta: float) -> np.ndarray:
    """Gravity of magnitude 9.81 at ``theta`` from −z, leaning towards :data:`AZIMUTH`."""
    return G * np.array([math.sin(theta) * math.cos(AZIMUTH), math.sin(theta) * math.sin(AZIMUTH), -math.cos(theta)])


def resting(box: robodyn.Robot, normal: np.ndarray) -> np.ndarray:
    """The box's bottom face on the plane of unit ``normal`` through the origin."""
    q = box.neutral_configuration()
    q[:3] = HALF_HEIGHT * normal
    rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), normal)
    q[3:7] = rotation.coeffs()  # x, y, z, w
    return q


@pytest.mark.parametrize(("degrees", "friction"), [(15.0, 0.5), (35.0, 0.5)])
def test_a_box_on_flat_ground_under_tilted_gravity_sticks_or_slides_by_coulombs_law(degrees, friction):
    theta = math.radians(degrees)
    gravity = tilted_gravity(theta)
    box = robodyn.load(BOX, floating_base=True, gravity=gravity)
    up = np.array([0.0, 0.0, 1.0])
    q0 = resting(box, up)
    run = simulate_contact(box, ground=Ground(friction=friction), duration=0.12, dt=1e-3, q0=q0)
    q = run.trajectory.q
    assert np.abs(q[:, 2] - HALF_HEIGHT).max() < 1e-9  # on the plane throughout
    if math.tan(theta) < friction:  # sticks: it stays, the ground carries −m g, tangential part included
        assert np.abs(q[-1, :3] - q0[:3]).max() < 1e-9
        np.testing.assert_allclose(run.forces[-1].sum(axis=0), -MASS * gravity, rtol=0, atol=1e-6 * MASS * G)
    else:  # slides down the gravity's horizontal direction, never across it
        along = np.array([math.cos(AZIMUTH), math.sin(AZIMUTH), 0.0])
        t = run.trajectory.t
        acceleration = 2 * np.polyfit(t[10:], (q[:, :3] @ along)[10:], 2)[0]
        assert abs(acceleration / (G * (math.sin(theta) - friction * math.cos(theta))) - 1) < 1e-3
        across = np.cross(up, along)
        assert np.abs(q[:, :3] @ across).max() < 1e-9


def test_a_box_on_a_frictionless_plane_normal_to_tilted_gravity_stays_put():
    gravity = tilted_gravity(math.radians(25.0))
    normal = -gravity / np.linalg.norm(gravity)
    box = robodyn.load(BOX, floating_base=True, gravity=gravity)
    q0 = resting(box, normal)
    run = simulate_contact(box, ground=Ground(normal=tuple(normal), friction=0.0), duration=0.05, dt=1e-3, q0=q0)
    assert np.abs(run.trajectory.q[-1, :3] - q0[:3]).max() < 1e-9
    np.testing.assert_allclose(run.forces[-1].sum(axis=0), -MASS * gravity, rtol=0, atol=1e-6 * MASS * G)


@pytest.mark.slow
def test_a_damped_pendulum_run_with_a_ground_loses_what_its_damping_dissipates():
    """The contact step's explicit joint damping (``−b v``), on a fixed-base pendulum with
    armature under tilted gravity, the ground out of reach: the energy lost is ``Σ b v² dt``
    to within semi-implicit Euler's energy wobble; without joint friction none is lost."""
    robot = robodyn.load(
        BOX.parent.parent / "robots" / "damped_pendulum.urdf", gravity=(1.0, -2.0, -9.0), armature={"hinge": 0.02}
    )
    dt = 1e-3

    def run(joint_friction: bool) -> tuple[np.ndarray, np.ndarray]:
        trajectory = robodyn.simulate(
            robot,
            np.array([1.0]),
            np.array([0.0]),
            0.5,
            dt,
            ground=Ground(height=-10.0),
            contacts=["pole"],
            integrator="semi-implicit-euler",
            joint_friction=joint_friction,
        )
        energy = np.array(
            [robot.kinetic_energy(q, v) + robot.potential_energy(q) for q, v in zip(trajectory.q, trajectory.v, strict=True)]
        )
        return energy, trajectory.v[:, 0]

    energy, speed = run(True)
    dissipated = np.concatenate([[0.0], np.cumsum(robot.joint_damping[0] * speed[1:] ** 2 * dt)])
    assert dissipated[-1] > 0.3  # [J]
    np.testing.assert_allclose(energy[0] - energy, dissipated, rtol=0, atol=0.015 * dissipated[-1])
    passive, _ = run(False)
    assert np.abs(passive - passive[0]).max() < 0.015 * dissipated[-1]  # the control: no loss without it
