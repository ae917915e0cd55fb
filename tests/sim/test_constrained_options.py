"""Issue 39, simulation under constraints crossed with the options: the joints' damping (a
mimic joint's own included), armature, tilted gravity and a floating base. The law is the
power balance of a passive constrained motion — the constraint forces do no work, so the
energy lost is the damping's ``∫ vᵀ D v dt`` — with the undamped run as its negative control
(it keeps its energy, so the loss is the damping's and not the integrator's)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointAnchor, PointContact
from tests.constraints.linkages import closed_configuration, load_linkage

DATA = Path(__file__).resolve().parent.parent / "data"
TILTED = (1.2, -9.7, 0.5)
DAMPING = {"shoulder": 0.05, "elbow": 0.08, "wrist": 0.03, "crank_joint": 0.002, "coupler_joint": 0.005, "rocker_joint": 0.003}

CASES = {
    # the mimic arm's tip sliding on an oblique frictionless plane through where it is at
    # q = (0.3, −0.4) (wrist = −1.5 elbow + 0.2: the elbow feels 0.08 + 1.5² · 0.03)
    "mimic arm, armature": (
        DATA / "mimic_arm.urdf",
        [
            PointContact(
                "tip", normal=(0.3, -0.2, 1.0), friction=0.0, plane_point=(0.45504425, 0.14076168, 0.2668255), name="plane"
            )
        ],
        {"gravity": TILTED, "armature": {"shoulder": 0.02, "wrist": 0.01}},
    ),
    "floating four-bar": (
        DATA / "constraints" / "four_bar_3d.urdf",
        [PointAnchor("coupler", (0.33, 0.0, 0.0), "rocker", (0.28, 0.0, 0.0), name="loop")],
        {"gravity": TILTED, "floating_base": True},
    ),
}


def damped(path: Path) -> str:
    """The file's text with ``<dynamics damping>`` on each of its moving joints."""

    def add(match: re.Match) -> str:
        name = match.group(1)
        return match.group(0) + (f'<dynamics damping="{DAMPING[name]}"/>' if name in DAMPING else "")

    return re.sub(r'<joint name="([^"]+)" type="(?:revolute|continuous|prismatic)"[^>]*>', add, path.read_text())


def energy(robot: robodyn.Robot, trajectory) -> np.ndarray:
    q, v = trajectory.q, trajectory.v
    return np.array([robot.kinetic_energy(qi, vi) + robot.potential_energy(qi) for qi, vi in zip(q, v, strict=True)])


@pytest.mark.parametrize("name", list(CASES))
def test_a_damped_closed_chain_loses_exactly_the_energy_its_damping_dissipates(name):
    path, constraints, options = CASES[name]
    robot = robodyn.load(damped(path), constraints=constraints, **options)
    assert robot.joint_damping.max() > 0
    rng = np.random.default_rng(3)
    if robot.mimic is not None:
        q0 = np.array([0.3, -0.4])
    else:  # the loop closed at a crank angle of 0.7 rad, the base tilted
        q0 = robot.floating_configuration(
            [0.1, 0.2, 0.3], [0.2, -0.1, 0.4], closed_configuration(load_linkage(name="four_bar_3d"), "four_bar_3d", 0.7)
        )
    v0 = 0.5 * rng.normal(size=robot.nv)
    run = robodyn.simulate(robot, q0, v0, duration=0.06, dt=2e-3)
    passive = robodyn.simulate(robot, q0, v0, duration=0.06, dt=2e-3, joint_friction=False)
    e, e_passive = energy(robot, run), energy(robot, passive)
    power = np.einsum("ni,i,ni->n", run.v, robot.joint_damping, run.v)  # vᵀ D v, D the folded damping
    dissipated = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(run.t))])
    loss = e[0] - e[-1]
    assert loss > 2e-4  # the damping took energy, in [J]
    assert abs(e_passive[-1] - e_passive[0]) < 1e-3 * loss  # negative control: without it, none
    np.testing.assert_allclose(e[0] - e, dissipated, rtol=0, atol=2e-3 * loss)
