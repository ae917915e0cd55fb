"""An outside reader: every test robot also read by a URDF parser robodyn does not share.

The reference reads the same ``URDFSpec`` as the dynamics, so a mistake in reading a file
(a default, an attribute's unit or order, a rotation convention) is made by both. Here the
raw file is also read by Pinocchio's own ``buildModelFromUrdf`` (urdfdom) and by MuJoCo's
URDF importer, and masses, inertias, joint placements, axes, limits and τ, M, G are
compared with the ``Robot``'s. Mimic joints are projected by hand from the raw XML
(``θ_mimic = multiplier θ_source + offset``). MuJoCo fuses fixed links and ignores
``<mimic>``: it is compared on robots without mimic joints, by total mass, joint axes and
anchors in the world, limits, and τ, M, G.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from tests.conftest import NONDEGENERATE, URDF_FILES
from tests.differential.cases import BASE_LINK, DATA_FILES, random_gravity
from tests.random_robots import urdf_from_seed

pytestmark = pytest.mark.differential

#: URDFs that lean on the defaults: no <origin> (identity), no <axis> (x), no <limit> on a
#: continuous joint, no <inertial> on a link (massless, welded to a massive one), an
#: inertial without <origin>, rpy with all three angles, inertia off-diagonals.
DEFAULTS = """<?xml version="1.0"?>
<robot name="defaults">
  <link name="base"/>
  <joint name="spin" type="continuous"><parent link="base"/><child link="a"/></joint>
  <link name="a"><inertial><mass value="1.7"/>
    <inertia ixx="0.03" ixy="0.004" ixz="-0.002" iyy="0.05" iyz="0.003" izz="0.04"/></inertial></link>
  <joint name="tilt" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 -0.1 0.15" rpy="0.3 -0.5 1.1"/>
    <limit lower="-1.2" upper="0.9" effort="20" velocity="3"/></joint>
  <link name="b"><inertial><origin xyz="0.1 0.03 -0.02" rpy="-0.4 0.2 0.7"/><mass value="0.9"/>
    <inertia ixx="0.01" ixy="-0.001" ixz="0.0015" iyy="0.012" iyz="0.0007" izz="0.009"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="b"/><child link="empty"/><origin rpy="0.2 0.1 -0.3"/></joint>
  <link name="empty"/>
  <joint name="slide" type="prismatic"><parent link="empty"/><child link="c"/>
    <origin xyz="0.05 0.02 0.3"/><axis xyz="0 1 1"/>
    <limit lower="-0.1" upper="0.2" effort="50" velocity="0.5"/></joint>
  <link name="c"><inertial><origin xyz="0 0.02 0.01"/><mass value="0.6"/>
    <inertia ixx="0.004" ixy="0.0002" ixz="0" iyy="0.005" iyz="-0.0003" izz="0.0045"/></inertial></link>
  <joint name="wrist" type="revolute"><parent link="c"/><child link="d"/>
    <origin xyz="0.1 0 0" rpy="1.2 0.4 -0.8"/><axis xyz="0 0 -2"/>
    <limit lower="-2" upper="2" effort="5" velocity="4"/></joint>
  <link name="d"><inertial><mass value="0.4"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.0025"/></inertial></link>
</robot>
"""

#: A chain of continuous joints only, none with <limit>, <origin> or <axis> but the last.
CONTINUOUS = """<?xml version="1.0"?>
<robot name="continuous_defaults">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="c1" type="continuous"><parent link="base"/><child link="l1"/></joint>
  <link name="l1"><inertial><origin xyz="0 0.1 0.2" rpy="0.1 0.2 0.3"/><mass value="1"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0.002" iyy="0.03" iyz="0.001" izz="0.025"/></inertial></link>
  <joint name="c2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="0 0.3 0"/></joint>
  <link name="l2"><inertial><origin xyz="0.05 0.1 0"/><mass value="0.8"/>
    <inertia ixx="0.01" ixy="0" ixz="0.001" iyy="0.012" iyz="0" izz="0.011"/></inertial></link>
  <joint name="c3" type="continuous"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.1 0.2 -0.1" rpy="-0.7 0.3 2.9"/><axis xyz="0.3 -0.4 1.2"/></joint>
  <link name="l3"><inertial><mass value="0.5"/><inertia ixx="0.004" ixy="0.001" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial></link>
</robot>
"""

WRITTEN = {"defaults": DEFAULTS, "continuous_defaults": CONTINUOUS}
FILES = [*URDF_FILES, *DATA_FILES, *sorted(NONDEGENERATE.glob("*.urdf"))]


def _random_tree_text(seed: int) -> str:
    return urdf_from_seed(seed, 5, ["revolute", "fixed", "continuous", "prismatic"]).replace('<link name="link0"/>', BASE_LINK)


def _sources(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("outside")
    paths = {path.name: path for path in FILES}
    for name, text in [*WRITTEN.items(), ("random_tree_7.urdf", _random_tree_text(7))]:
        paths[name] = folder / f"{name}.urdf" if not name.endswith(".urdf") else folder / name
        paths[name].write_text(text)
    return paths


SOURCE_NAMES = [path.name for path in FILES] + [*WRITTEN, "random_tree_7.urdf"]


@pytest.fixture(scope="module")
def sources(tmp_path_factory) -> dict[str, Path]:
    return _sources(tmp_path_factory)


# ----------------------------------------------------------------------------------------
# Mimic joints and joint coordinates of the raw model, read from the XML by hand
# ----------------------------------------------------------------------------------------
def _mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    """mimic joint -> (source, multiplier, offset), URDF defaults 1 and 0."""
    out = {}
    for joint in ET.parse(path).getroot().iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None and joint.get("type") != "fixed":
            out[joint.get("name")] = (mimic.get("joint"), float(mimic.get("multiplier", "1")), float(mimic.get("offset", "0")))
    return out


class RawState:
    """Maps the Robot's (q, v, a) to the raw Pinocchio model's, mimic joints included, and
    projects its results back (``τ = Sᵀ τ_raw``, ``M = Sᵀ M_raw S``)."""

    def __init__(self, robot: robodyn.Robot, raw: pin.Model, mimics: dict) -> None:
        self.robot, self.raw, self.mimics = robot, raw, mimics
        base = 6 if robot.floating_base else 0
        names = list(robot.joint_names[1:] if robot.floating_base else robot.joint_names)
        self.selection = np.zeros((raw.nv, robot.nv))
        self.offset = np.zeros(raw.nv)
        self.selection[:base, :base] = np.eye(base)
        for joint_id in range(1 if not robot.floating_base else 2, raw.njoints):
            name, index = raw.names[joint_id], raw.joints[joint_id].idx_v
            source, multiplier, offset = mimics.get(name, (name, 1.0, 0.0))
            self.selection[index, base + names.index(source)] = multiplier
            self.offset[index] = offset
        self.base = base

    def q(self, q: np.ndarray) -> np.ndarray:
        theta = self.selection @ np.concatenate([np.zeros(self.base), q[7:] if self.base else q]) + self.offset
        out = pin.neutral(self.raw)
        if self.base:
            out[:7] = q[:7]
        for joint_id in range(2 if self.base else 1, self.raw.njoints):
            joint = self.raw.joints[joint_id]
            angle = theta[joint.idx_v]
            if joint.nq == 2:  # continuous: (cos, sin)
                out[joint.idx_q : joint.idx_q + 2] = np.cos(angle), np.sin(angle)
            else:
                out[joint.idx_q] = angle
        return out

    def tau_m_g(self, q, v, a, gravity):
        self.raw.gravity.linear = np.asarray(gravity, dtype=float)
        data = self.raw.createData()
        qr, vr, ar = self.q(q), self.selection @ v, self.selection @ a
        tau = pin.rnea(self.raw, data, qr, vr, ar).copy()
        mass = pin.crba(self.raw, data, qr)
        mass = np.triu(mass) + np.triu(mass, 1).T
        g = pin.computeGeneralizedGravity(self.raw, data, qr).copy()
        s = self.selection
        return s.T @ tau, s.T @ mass @ s, s.T @ g


def _relative(actual, expected) -> float:
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    return float(np.max(np.abs(actual - expected), initial=0.0) / max(np.max(np.abs(expected), initial=0.0), 1e-300))


# ----------------------------------------------------------------------------------------
# Pinocchio's own URDF parser (urdfdom) on the raw file
# ----------------------------------------------------------------------------------------
def _axis(model: pin.Model, joint_id: int) -> tuple[str, np.ndarray]:
    """A one-degree-of-freedom joint's kind ('R' or 'P') and unit axis in its own frame: its
    column of the joint Jacobian in the LOCAL frame (whatever Pinocchio's joint type)."""
    data = model.createData()
    q = pin.neutral(model)
    pin.computeJointJacobians(model, data, q)
    jacobian = pin.getJointJacobian(model, data, joint_id, pin.LOCAL).reshape(6, -1)  # (6,) for a 1-DoF model
    column = jacobian[:, model.joints[joint_id].idx_v]
    linear, angular = column[:3], column[3:]
    return ("P", linear) if np.linalg.norm(angular) < 1e-12 else ("R", angular)


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("name", SOURCE_NAMES)
def test_pinocchio_urdfdom_reads_the_file_as_robodyn_does(name, floating, sources):
    path = sources[name]
    rng = np.random.default_rng(len(name))
    gravity = random_gravity(rng)
    robot = robodyn.load(path, floating_base=floating, gravity=gravity)
    raw = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating else pin.buildModelFromUrdf(str(path))
    ours = robot.model
    mimics = _mimics(path)
    names = [ours.names[j] for j in range(1, ours.njoints)]
    assert sorted(names) == sorted(raw.names[j] for j in range(1, raw.njoints)), name
    total = sum(raw.inertias[j].mass for j in range(raw.njoints))
    assert total == pytest.approx(sum(ours.inertias[j].mass for j in range(ours.njoints)), rel=1e-12)
    for joint_name in names:
        j, k = ours.getJointId(joint_name), raw.getJointId(joint_name)
        placement, theirs = ours.jointPlacements[j], raw.jointPlacements[k]
        assert np.allclose(placement.homogeneous, theirs.homogeneous, atol=1e-12), f"{joint_name} placement"
        if joint_name != "root_joint" and joint_name not in mimics:  # (a mimic's column is its source's)
            kind, axis = _axis(ours, j)
            raw_kind, raw_axis = _axis(raw, k)
            assert kind == raw_kind, f"{joint_name} kind"
            assert np.allclose(axis, raw_axis, atol=1e-12), f"{joint_name} axis {axis} vs {raw_axis}"
        mine, other = ours.inertias[j], raw.inertias[k]
        assert mine.mass == pytest.approx(other.mass, rel=1e-12), f"{joint_name} mass"
        assert np.allclose(mine.lever, other.lever, atol=1e-12), f"{joint_name} centre of mass"
        assert np.allclose(mine.inertia, other.inertia, atol=1e-12), f"{joint_name} inertia"
        joint = raw.joints[k]
        if joint_name in robot.joint_names and joint_name != "root_joint" and joint.nq == 1:  # limits
            dof = robot.dofs[[d.joint for d in robot.dofs].index(joint_name)]
            limits = (dof.lower, dof.upper, dof.effort_limit, dof.velocity_limit)
            theirs = (raw.lowerPositionLimit[joint.idx_q], raw.upperPositionLimit[joint.idx_q], raw.effortLimit[joint.idx_v],
                      raw.velocityLimit[joint.idx_v])  # fmt: skip
            assert limits == pytest.approx(theirs), f"{joint_name} limits"
    state = RawState(robot, raw, _mimics(path))
    q = robot.random_configuration(rng, 3)
    if floating:
        q[0] = robot.floating_configuration([0.3, -0.2, 0.5], [0.4, -0.3, 0.9], q[0, 7:])
    for row in range(3):
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        tau, mass, g = state.tau_m_g(q[row], v, a, gravity)
        assert _relative(robot.inverse_dynamics(q[row], v, a), tau) < 1e-9, f"{name}: tau"
        assert _relative(robot.mass_matrix(q[row]), mass) < 1e-9, f"{name}: M"
        assert _relative(robot.gravity(q[row]), g) < 1e-9 or np.max(np.abs(g)) < 1e-9 * np.max(np.abs(tau)), f"{name}: G"


def test_the_outside_reader_sees_a_misread_default(sources, monkeypatch):
    """Negative control: robodyn reading a missing <axis> as z instead of x is caught."""
    from robodyn.urdf import validation

    path = sources["defaults"]
    raw = pin.buildModelFromUrdf(str(path))
    original = validation._Reader.floats

    def misread(self, where, node, attribute, default):
        if attribute == "xyz" and default == "1 0 0":
            default = "0 0 1"
        return original(self, where, node, attribute, default)

    monkeypatch.setattr(validation._Reader, "floats", misread)
    robot = robodyn.load(path)
    j = robot.model.getJointId("spin")
    assert not np.allclose(_axis(robot.model, j)[1], _axis(raw, raw.getJointId("spin"))[1])


# ----------------------------------------------------------------------------------------
# MuJoCo's URDF importer
# ----------------------------------------------------------------------------------------
def _mujoco(path: Path, gravity):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.gravity[:] = gravity
    return mujoco, model


MUJOCO_NAMES = [name for name in SOURCE_NAMES if "mimic" not in name and "gripper" not in name]


@pytest.mark.parametrize("name", MUJOCO_NAMES)
def test_mujoco_reads_the_file_as_robodyn_does(name, sources):
    path = sources[name]
    if _mimics(path):
        pytest.skip("MuJoCo ignores <mimic>")
    rng = np.random.default_rng(len(name) + 1)
    gravity = random_gravity(rng)
    robot = robodyn.load(path, floating_base=False, gravity=gravity)
    mujoco, model = _mujoco(path, gravity)
    data = mujoco.MjData(model)
    moving = sum(robot.model.inertias[j].mass for j in range(1, robot.model.njoints))  # MuJoCo fuses the rest into the world
    assert float(np.sum(model.body_mass)) == pytest.approx(moving, rel=1e-9)
    names = list(robot.joint_names)
    addresses = [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)] for joint in names]
    dof = [model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)] for joint in names]
    assert model.nv == robot.nv
    for _ in range(3):
        q = robot.random_configuration(rng)
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        data.qpos[addresses], data.qvel[dof], data.qacc[dof] = q, v, a
        mujoco.mj_forward(model, data)
        kinematics = robot.model.createData()
        pin.forwardKinematics(robot.model, kinematics, q)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, full)
        mass = full[np.ix_(dof, dof)]
        tau = mass @ a + data.qfrc_bias[dof]
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        g = data.qfrc_bias[dof].copy()
        assert _relative(robot.mass_matrix(q), mass) < 1e-9, f"{name}: M"
        assert _relative(robot.inverse_dynamics(q, v, a), tau) < 1e-9, f"{name}: tau"
        assert _relative(robot.gravity(q), g) < 1e-9 or np.max(np.abs(g)) < 1e-9 * np.max(np.abs(tau)), f"{name}: G"
        for joint in names:  # axes in the world
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            frame = robot.model.getJointId(joint)
            pose = kinematics.oMi[frame]
            axis = _axis(robot.model, frame)[1]
            assert np.allclose(data.xaxis[jid], pose.rotation @ axis, atol=1e-9), f"{joint} axis"
    for joint in names:  # limits of limited joints
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        k = robot.joint_names.index(joint)
        if model.jnt_limited[jid]:
            assert model.jnt_range[jid] == pytest.approx([robot.lower_limits[k], robot.upper_limits[k]]), f"{joint} range"
        else:
            assert not np.isfinite(robot.upper_limits[k]), f"{joint}: MuJoCo reads no limit"
