"""Issue 39, control in contact crossed with the load options: the hybrid force/motion law's
promise — the contact force is the command at every instant — at random states on an
oblique frictionless surface (velocities along it), on a pairwise-covering set of (robot:
a 6-joint arm or the panda with its mimic finger, gravity, armature, a locked joint). The
plant is the robot with the options; the negative control is the same law built on a model
without this case's gravity or armature (the force misses the command by newtons). A floating
base is not crossed: the law assumes every coordinate actuated; a 2-joint arm neither (a 3-D
task it cannot span)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.sim.force_control import HybridForceMotion
from tests.dynamics.test_constrained_options import pairwise

NORMAL = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
FORCE = 7.0  # [N]
OBLIQUE = (1.2, -9.7, 0.5)
OPTIONS = {
    "ur5": ({"elbow_joint": 0.3, "wrist_1_joint": 0.1}, {"elbow_joint": 1.0}),
    "panda": ({"panda_joint2": 0.2, "panda_joint6": 0.1}, {"panda_joint3": 0.3}),
}
CASES = pairwise({"robot": list(OPTIONS), "gravity": [None, OBLIQUE], "armature": [False, True], "lock": [False, True]})


def options(case: dict, *, without: str | None = None) -> dict:
    armature, lock = OPTIONS[case["robot"]]
    chosen = {
        "gravity": case["gravity"],
        "armature": armature if case["armature"] else None,
        "lock": lock if case["lock"] else None,
    }
    return {key: value for key, value in chosen.items() if value is not None and key != without}


def contact_force(plant: robodyn.Robot, model: robodyn.Robot, rng: np.random.Generator) -> float:
    """The surface's normal force on the plant driven by the law built on ``model``, at a
    random configuration touching the surface and a random velocity along it."""
    q = plant.random_configuration(rng)
    frame = plant.task_frame(None, "hybrid force/motion control")
    x = plant.frame_position(q, frame)
    surface = PointContact(frame, normal=tuple(NORMAL), friction=0.0, plane_point=tuple(x))
    jacobian, mass = plant.constraint_jacobian(q, [surface]), plant.mass_matrix(q)
    response = np.linalg.solve(mass, jacobian.T)
    v = rng.normal(size=plant.nv)
    v = v - response @ np.linalg.solve(jacobian @ response, jacobian @ v)  # along the surface
    control = HybridForceMotion(model, None, NORMAL, FORCE, x + np.array([0.02, 0.01, -0.03]))
    _, multipliers = plant.constrained_forward_dynamics(q, v, control(0.0, q, v), [surface])
    return float(multipliers[0])


@pytest.mark.parametrize("case", CASES, ids=lambda case: "-".join(f"{key}={value}" for key, value in case.items()))
def test_the_contact_force_is_the_command_under_every_option(case):
    plant = robodyn.load(case["robot"], **options(case))
    rng = np.random.default_rng(39)
    for _ in range(2):
        assert abs(contact_force(plant, plant, rng) - FORCE) <= 1e-9 * FORCE
    for dropped in ("gravity", "armature"):
        if case[dropped]:
            model = robodyn.load(case["robot"], **options(case, without=dropped))
            assert abs(contact_force(plant, model, rng) - FORCE) > 0.1 * FORCE, dropped
