"""robodyn against MuJoCo's own model of a file: τ (mj_inverse), M (mj_fullM) and the bias
at rest (qfrc_bias = G), with states mapped by MuJoCo's own data — joints by name, each
joint's qpos0 (MuJoCo's ``ref``) added, the free joint's w-first quaternion and world-frame
linear velocity — never by robodyn's conversion. Also MuJoCo's actuator limits by joint,
from its compiled arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robodyn

mujoco = pytest.importorskip("mujoco")


def rigid_model(path) -> mujoco.MjModel:
    """MuJoCo's model of a file with what robodyn's rigid-body dynamics leaves out switched
    off (constraints, damping, springs, fluid); its gravity and armature kept."""
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    model.dof_damping[:] = 0
    model.jnt_stiffness[:] = 0
    model.opt.density, model.opt.viscosity = 0.0, 0.0
    return model


def _rotation(xyzw: np.ndarray) -> np.ndarray:
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, np.array([xyzw[3], *xyzw[:3]]) / np.linalg.norm(xyzw))
    return matrix.reshape(3, 3)


def mujoco_state(robot: robodyn.Robot, model, q, v, a, *, refs: bool = True):
    """MuJoCo's qpos, qvel, qacc of robodyn's (q, v, a), and T with qvel = T v (``refs``
    false: MuJoCo's qpos0 not added, the negative control)."""
    qpos, transform = np.zeros(model.nq), np.zeros((model.nv, robot.nv))
    bias = np.zeros(model.nv)
    for joint in range(model.njnt):
        adr, dof = model.jnt_qposadr[joint], model.jnt_dofadr[joint]
        if model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            rotation = _rotation(q[3:7])
            qpos[adr : adr + 7] = [*q[:3], q[6], *q[3:6]]
            transform[dof : dof + 3, :3] = rotation
            transform[dof + 3 : dof + 6, 3:6] = np.eye(3)
            bias[dof : dof + 3] = rotation @ np.cross(v[3:6], v[:3])
            continue
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        qpos[adr] = q[robot.configuration_names.index(name)] + (model.qpos0[adr] if refs else 0.0)
        transform[dof, robot.dofs.index(next(d for d in robot.dofs if d.name == name))] = 1
    return qpos, transform @ v, transform @ a + bias, transform


def largest_differences(robot: robodyn.Robot, model, samples: int = 6, seed: int = 4, *, refs: bool = True) -> np.ndarray:
    """Largest |τ|, |M| and |G| differences over random states (MuJoCo's gravity: the file's)."""
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    worst = np.zeros(3)
    for q in robot.random_configuration(rng, samples):
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        data.qpos[:], data.qvel[:], data.qacc[:], transform = mujoco_state(robot, model, q, v, a, refs=refs)
        mujoco.mj_inverse(model, data)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, full) if not hasattr(data, "qM") else mujoco.mj_fullM(model, full, data.qM)
        tau = transform.T @ data.qfrc_inverse
        mass = transform.T @ full @ transform
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        gravity = transform.T @ data.qfrc_bias
        worst = np.maximum(
            worst,
            [
                np.abs(tau - robot.inverse_dynamics(q, v, a)).max(),
                np.abs(mass - robot.mass_matrix(q)).max(),
                np.abs(gravity - robot.gravity(q)).max(),
            ],
        )
    return worst


def mujoco_effort_limits(model) -> dict[str, float]:
    """Each joint's largest actuator force magnitude as MuJoCo bounds it: per actuator with a
    joint transmission, gain × ctrlrange where the force is the control (fixed gain, no bias,
    ctrllimited), within forcerange, times gear; summed over the joint's actuators; within the
    joint's actuatorfrcrange."""
    ranges: dict[int, list[float]] = {}
    for actuator in range(model.nu):
        if model.actuator_trntype[actuator] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        low, high = -math.inf, math.inf
        control = model.actuator_gaintype[actuator] == 0 and model.actuator_biastype[actuator] == 0
        if control and model.actuator_ctrllimited[actuator]:
            low, high = sorted(model.actuator_gainprm[actuator, 0] * model.actuator_ctrlrange[actuator])
        if model.actuator_forcelimited[actuator]:
            low, high = max(low, model.actuator_forcerange[actuator, 0]), min(high, model.actuator_forcerange[actuator, 1])
        gear = model.actuator_gear[actuator, 0]
        low, high = sorted((gear * low, gear * high))
        joint = int(model.actuator_trnid[actuator, 0])
        previous = ranges.get(joint, [0.0, 0.0])
        ranges[joint] = [previous[0] + low, previous[1] + high]
    limits = {}
    for joint in range(model.njnt):
        low, high = ranges.get(joint, [-math.inf, math.inf])
        if model.jnt_actfrclimited[joint]:
            low, high = max(low, model.jnt_actfrcrange[joint, 0]), min(high, model.jnt_actfrcrange[joint, 1])
        limits[mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)] = max(abs(low), abs(high))
    return limits
