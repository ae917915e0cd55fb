"""The closed chains of the constraint tests (tests/data/constraints), their constraints,
closed configurations from their analytic position solution, and Pinocchio's own
``constraintDynamics`` called directly (the outside check of robodyn's KKT solve)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin

import robodyn
from robodyn.common.rotations import rpy_matrix
from robodyn.constraints import FrameAnchor, PointAnchor

DATA = Path(__file__).resolve().parent.parent / "data" / "constraints"
#: Not the default gravity: tilted, and not in the mechanisms' planes or normal to them.
GRAVITY = (1.2, -9.7, 0.5)
#: Bar lengths (crank a, coupler b, rocker c, ground d) of each four-bar file.
FOUR_BARS = {
    "four_bar": (0.1, 0.35, 0.3, 0.4),
    "four_bar_3d": (0.12, 0.33, 0.28, 0.38),
    "parallelogram": (0.3, 0.5, 0.3, 0.5),
}


def loop(name: str) -> PointAnchor:
    """The loop closure of a four-bar file: the coupler's tip held on the rocker's tip."""
    _, b, c, _ = FOUR_BARS[name]
    return PointAnchor("coupler", (b, 0.0, 0.0), "rocker", (c, 0.0, 0.0), name="loop")


def slider_loop() -> PointAnchor:
    """The slider–crank's closure: the rod's tip on the slider (oblique prismatic axis)."""
    return PointAnchor("rod", (0.4, 0.0, 0.0), "slider", (0.0, 0.0, 0.0), name="slider pin")


def load_linkage(name: str, **options) -> robodyn.Robot:
    """A linkage of tests/data/constraints with its loop closed, under :data:`GRAVITY`."""
    closure = slider_loop() if name == "slider_crank" else loop(name)
    return robodyn.load(DATA / f"{name}.urdf", gravity=GRAVITY, constraints=[closure], **options)


def rocker_angle(name: str, crank: float, branch: int = 1) -> float:
    """The rocker's angle from the ground line for a crank angle: the closed form (two
    circles' intersection, which satisfies Freudenstein's equation)."""
    a, b, c, d = FOUR_BARS[name]
    ax, ay = a * math.cos(crank), a * math.sin(crank)
    dx, dy = d - ax, -ay
    e = math.hypot(dx, dy)
    # angle at D between D→A and D→B (law of cosines in triangle A B D)
    gamma = math.acos((c * c + e * e - b * b) / (2 * c * e))
    return math.atan2(-dy, -dx) - branch * gamma


def freudenstein(name: str, crank: float, rocker: float) -> float:
    """Freudenstein's equation's residual, ``K1 cos θ4 − K2 cos θ2 + K3 − cos(θ2 − θ4)``."""
    a, b, c, d = FOUR_BARS[name]
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    return k1 * math.cos(rocker) - k2 * math.cos(crank) + k3 - math.cos(crank - rocker)


def closed_configuration(robot: robodyn.Robot, name: str, crank: float) -> np.ndarray:
    """``q`` of a four-bar with its loop closed at a crank angle (joints by name)."""
    a, _, _, d = FOUR_BARS[name]
    rocker = rocker_angle(name, crank)
    tip = np.array([d + FOUR_BARS[name][2] * math.cos(rocker), FOUR_BARS[name][2] * math.sin(rocker)])
    coupler = math.atan2(tip[1] - a * math.sin(crank), tip[0] - a * math.cos(crank)) - crank
    values = {"crank_joint": crank, "coupler_joint": coupler, "rocker_joint": rocker}
    return np.array([values[joint] for joint in robot.joint_names])


def _pinocchio_constraint(model: pin.Model, anchor) -> pin.RigidConstraintModel:
    """Pinocchio's constraint of a point anchor (both points given: CONTACT_3D) or a weld to
    where it is at the neutral configuration (CONTACT_6D), world-aligned."""
    first = model.frames[model.getFrameId(anchor.frame1)]
    second = model.frames[model.getFrameId(anchor.frame2)]
    if isinstance(anchor, FrameAnchor):
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        local = pin.SE3(rpy_matrix(np.array(anchor.origin1[3:])), np.array(anchor.origin1[:3]))
        world = data.oMf[model.getFrameId(anchor.frame1)] * local
        held = second.placement * (data.oMf[model.getFrameId(anchor.frame2)].inverse() * world)
        kind, placement1, placement2 = pin.ContactType.CONTACT_6D, first.placement * local, held
    else:
        kind = pin.ContactType.CONTACT_3D
        placement1 = first.placement * pin.SE3(np.eye(3), np.array(anchor.point1))
        placement2 = second.placement * pin.SE3(np.eye(3), np.array(anchor.point2))
    return pin.RigidConstraintModel(
        kind, model, first.parentJoint, placement1, second.parentJoint, placement2, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )


def pinocchio_constraint_dynamics(robot: robodyn.Robot, anchors, q, v, tau) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's ``constraintDynamics`` with point anchors and welds (world-aligned), called directly.

    For a redundant set, Pinocchio's ``λ`` carries its rounding in the redundant direction
    amplified by ``1/μ`` (about 1e-8 here): ``λ`` is returned as the least-norm multipliers
    with Pinocchio's ``Jᵀ λ`` (its component on the null space of ``Jᵀ`` removed).
    """
    model = robot.model
    data = model.createData()
    models = pin.StdVec_RigidConstraintModel()
    for anchor in anchors:
        models.append(_pinocchio_constraint(model, anchor))
    datas = pin.StdVec_RigidConstraintData()
    for constraint in models:
        datas.append(constraint.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    # μ = 1e-6: a redundant row's rounding (1e-16) enters λ as 1e-16/μ, and the iteration
    # still converges in a few steps (the Delassus eigenvalues are 1e-3 and more)
    settings = pin.ProximalSettings(1e-14, 1e-6, 500)
    acceleration = pin.constraintDynamics(model, data, q, v, tau, models, datas, settings)
    transpose = robot.constraint_jacobian(q, anchors).T
    return acceleration.copy(), np.linalg.pinv(transpose, rcond=1e-10) @ (transpose @ data.lambda_c)
