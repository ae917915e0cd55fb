"""Joint damping, friction and armature: read from the file, in the model, in every dynamics call.

Checked against readers and engines outside robodyn: Pinocchio's own URDF parser on the raw
file (damping, friction), MuJoCo (``mj_fullM``, ``mj_inverse``, ``mj_energyVel`` with
``dof_armature`` set, its URDF reader's ``dof_damping``), and the reference (which never
imports Pinocchio: armature as rotor bodies).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn import reference
from robodyn.exceptions import InputError
from tests.conftest import NONDEGENERATE, random_states

mujoco = pytest.importorskip("mujoco")

OBLIQUE = NONDEGENERATE / "oblique.urdf"
GRIPPER = NONDEGENERATE / "mimic_gripper.urdf"
#: Armature on every joint of the oblique robot (revolute, prismatic on an oblique axis, continuous).
OBLIQUE_ARMATURE = {"j_yaw": 0.031, "j_twist": 0.017, "j_extend": 0.4, "j_tool": 0.0023}
GRAVITY = [0.3, -0.4, -9.6]


def with_dynamics(path, values: dict[str, str]) -> str:
    """The URDF at ``path`` with ``<dynamics .../>`` (attribute text) put into the named joints."""
    text = path.read_text(encoding="utf-8")
    for joint, attributes in values.items():
        text, count = re.subn(rf'(<joint name="{joint}"[^>]*>)', rf"\1<dynamics {attributes}/>", text)
        assert count == 1
    return text


def mujoco_model(robot):
    """MuJoCo's model of the robot's URDF (its own reader: damping and friction from
    ``<dynamics>``), contacts and limits off, gravity as the robot's."""
    root = ET.fromstring(robot.urdf)
    ET.SubElement(
        ET.SubElement(root, "mujoco"), "compiler", {"discardvisual": "true", "fusestatic": "false", "balanceinertia": "false"}
    )
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    model.opt.gravity[:] = robot.gravity_vector
    return model


def mujoco_terms(robot, model, q, v, a):
    """MuJoCo's ``M`` (mj_fullM), ``qfrc_inverse`` (mj_inverse) and kinetic energy at one
    state, in the robot's order of coordinates."""
    dofs = [model.joint(name).dofadr[0] for name in robot.joint_names]
    data = mujoco.MjData(model)
    data.qpos[[model.joint(name).qposadr[0] for name in robot.joint_names]] = q
    data.qvel[dofs], data.qacc[dofs] = v, a
    mujoco.mj_inverse(model, data)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    mujoco.mj_forward(model, data)
    return mass[np.ix_(dofs, dofs)], data.qfrc_inverse[dofs], float(data.energy[1])


def test_damping_and_friction_are_what_pinocchios_own_parser_reads_from_the_raw_file():
    """Zoo robots with ``<dynamics>`` (panda: mimic fingers; z1, talos_arm, xarm7: friction
    too) and the oblique robot: Pinocchio's buildModelFromUrdf on the user's file, not on
    robodyn's copy. A mimic joint's values are folded onto its source (k² b, |k| f)."""
    for name in ("panda", "z1", "talos_arm", "xarm7", OBLIQUE):
        robot = robodyn.load(name)
        raw = pin.buildModelFromUrdf(str(robot.source_path), mimic=False)
        expected = {"damping": np.zeros(robot.nv), "friction": np.zeros(robot.nv)}
        for joint_id in range(1, raw.njoints):
            joint = robot.spec.joints[raw.names[joint_id]]
            source, k = (joint.name, 1.0) if joint.mimic is None else (joint.mimic.joint, joint.mimic.multiplier)
            index = robot.joint_names.index(source)
            expected["damping"][index] += k**2 * raw.damping[raw.joints[joint_id].idx_v]
            expected["friction"][index] += abs(k) * raw.friction[raw.joints[joint_id].idx_v]
        assert expected["damping"].any()  # non-degenerate: the file has damping
        np.testing.assert_array_equal(robot.joint_damping, expected["damping"])
        np.testing.assert_array_equal(robot.joint_friction, expected["friction"])
        np.testing.assert_array_equal(robot.model.damping, expected["damping"])
        np.testing.assert_array_equal(robot.model.friction, expected["friction"])
        assert [dof.damping for dof in robot.dofs] == expected["damping"].tolist()
    panda = robodyn.load("panda")
    finger = panda.joint_names.index("panda_finger_joint1")
    assert panda.joint_damping[finger] == 2 * 0.3  # its mimic's 0.3 acts on it too


def test_armature_is_in_the_mass_matrix_and_the_torques_as_mujoco_has_them(rng):
    """oblique robot (oblique axes, a prismatic joint, a continuous one), non-default
    gravity, armature on every joint: M, tau (with the file's damping) and the kinetic
    energy equal MuJoCo's to 1e-10 with the same dof_armature."""
    robot = robodyn.load(OBLIQUE, armature=OBLIQUE_ARMATURE, gravity=GRAVITY)
    model = mujoco_model(robot)
    np.testing.assert_array_equal(model.dof_damping[[model.joint(n).dofadr[0] for n in robot.joint_names]], robot.joint_damping)
    model.dof_frictionloss[:] = 0.0  # MuJoCo's friction loss is a constraint force: compared in the simulation tests
    for name, value in OBLIQUE_ARMATURE.items():
        model.dof_armature[model.joint(name).dofadr[0]] = value
    q, v, a = random_states(robot, rng, 7)
    plain = robodyn.load(OBLIQUE, gravity=GRAVITY)
    for qi, vi, ai in zip(q, v, a, strict=True):
        mass, force, kinetic = mujoco_terms(robot, model, qi, vi, ai)
        scale = np.abs(mass).max()
        assert np.abs(robot.mass_matrix(qi) - mass).max() < 1e-10 * scale
        assert np.abs(robot.inverse_dynamics(qi, vi, ai) + robot.joint_damping * vi - force).max() < 1e-10 * np.abs(force).max()
        assert abs(robot.kinetic_energy(qi, vi) - kinetic) < 1e-10 * kinetic
        # negative control: the robot without armature is off by the armature's share
        assert np.abs(plain.mass_matrix(qi) - mass).max() > 1e-3 * scale
    assert np.abs(robot.forward_dynamics(q, v, robot.inverse_dynamics(q, v, a)) - a).max() < 1e-9


def test_armature_of_a_mimic_joint_acts_on_its_source_as_the_reference_has_it(rng):
    """mimic_gripper (prismatic mimic with k = −1.5, revolute mimics with 2.2 and 0.7),
    armature and damping on sources and mimics: M, tau, C, the energies and the batch paths
    (7 and 129 states) equal the reference's (rotor bodies through the mimic map)."""
    armature = {"j_right": 0.3, "j_thumb": 0.002, "j_rotate": 0.011, "j_lift": 0.5}
    text = with_dynamics(GRIPPER, {"j_thumb": 'damping="0.2" friction="0.1"', "j_rotate": 'damping="0.05"'})
    robot = robodyn.load(text, armature=armature, gravity=GRAVITY)
    model = reference.load(text, armature=armature, gravity=GRAVITY)
    plain = robodyn.load(text, gravity=GRAVITY)
    rotate, left = robot.joint_names.index("j_rotate"), robot.joint_names.index("j_left")
    assert robot.joint_armature[rotate] == pytest.approx(0.011 + 2.2**2 * 0.002)
    assert robot.joint_armature[left] == pytest.approx(1.5**2 * 0.3)
    assert robot.joint_damping[rotate] == pytest.approx(0.05 + 2.2**2 * 0.2)
    assert robot.joint_friction[rotate] == pytest.approx(2.2 * 0.1)
    order = [model.joint_names.index(name) for name in robot.joint_names]
    for count in (7, 129):
        q, v, a = random_states(robot, rng, count)
        mass = model.mass_matrix(q[:, order])[:, order][:, :, order]
        assert np.abs(robot.mass_matrix(q) - mass).max() < 1e-12 * np.abs(mass).max()
        tau = model.inverse_dynamics(q[:, order], v[:, order], a[:, order])[:, order]
        assert np.abs(robot.inverse_dynamics(q, v, a) - tau).max() < 1e-11 * np.abs(tau).max()
        assert np.abs(robot.forward_dynamics(q, v, tau) - a).max() < 1e-9
        kinetic = model.kinetic_energy(q[:, order], v[:, order])
        assert np.abs(robot.kinetic_energy(q, v) - kinetic).max() < 1e-12 * np.abs(kinetic).max()
        coriolis = model.coriolis_matrix(q[:, order], v[:, order])[:, order][:, :, order]
        assert np.abs(robot.coriolis_matrix(q, v) - coriolis).max() < 1e-11 * np.abs(coriolis).max()
        assert np.abs(plain.mass_matrix(q) - mass).max() > 1e-3  # negative control
    changed = reference.load(text, armature={**armature, "j_thumb": 0.003}, gravity=GRAVITY)
    assert np.abs(changed.mass_matrix(q[0, order]) - model.mass_matrix(q[0, order])).max() > 1e-4  # a changed armature shows


def test_inverse_dynamics_adds_the_joint_friction_torques_only_when_asked(rng):
    robot = robodyn.load(with_dynamics(GRIPPER, {"j_rotate": 'damping="0.05" friction="0.3"'}), floating_base=True)
    q, v, a = random_states(robot, rng, 7)
    v[0, robot.joint_names.index("j_rotate") + 5] = 0.0  # at rest: the Coulomb part is left out (sign 0)
    rigid = robot.inverse_dynamics(q, v, a)
    with_friction = robot.inverse_dynamics(q, v, a, joint_friction=True)
    expected = robot.joint_damping * v + robot.joint_friction * np.sign(v)
    np.testing.assert_allclose(with_friction - rigid, expected, atol=1e-12)
    assert robot.joint_damping.shape == robot.joint_friction.shape == robot.joint_armature.shape == (robot.nv,)
    assert not robot.joint_damping[:6].any() and not robot.joint_friction[:6].any()  # the floating base's six
    np.testing.assert_allclose(robot.inverse_dynamics(q[1], v[1], a[1], joint_friction=True), with_friction[1], atol=1e-12)


def test_an_armature_for_a_joint_the_robot_does_not_have_is_refused_with_the_joint_names():
    with pytest.raises(InputError) as raised:
        robodyn.load(OBLIQUE, armature={"j_elbow": 0.1})
    message = str(raised.value)
    assert raised.value.argument == "armature" and "'j_elbow'" in message
    assert all(f"'{name}'" in message for name in ("j_yaw", "j_twist", "j_extend", "j_tool"))
    assert "\n" not in message
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(InputError):
            robodyn.load(OBLIQUE, armature={"j_yaw": bad})
    with pytest.raises(InputError):
        reference.load(OBLIQUE, armature={"bracket": 0.1})  # a fixed joint has no armature


def test_a_locked_joint_takes_its_damping_friction_and_armature_with_it(rng):
    robot = robodyn.load(OBLIQUE, lock={"j_twist": 0.7}, armature={"j_twist": 0.2, "j_tool": 0.01})
    assert "j_twist" not in robot.joint_names
    assert not robot.joint_damping.any() and not robot.joint_friction.any()  # j_twist had them
    assert robot.joint_armature.tolist() == [0.0, 0.0, 0.01]
    model = reference.load(OBLIQUE, lock={"j_twist": 0.7}, armature={"j_twist": 0.2, "j_tool": 0.01})
    q, _, _ = random_states(robot, rng, 7)
    np.testing.assert_allclose(robot.mass_matrix(q), model.mass_matrix(q), atol=1e-12)


def test_a_rebuilt_or_unpickled_robot_keeps_its_armature():
    import pickle

    from robodyn.dynamics.loading import rebuild

    robot = robodyn.load(OBLIQUE, armature=OBLIQUE_ARMATURE)
    for copy in (rebuild(robot), pickle.loads(pickle.dumps(robot))):
        np.testing.assert_array_equal(copy.joint_armature, robot.joint_armature)
        np.testing.assert_array_equal(copy.model.armature, robot.model.armature)


@pytest.mark.parametrize("value", ["abc", float("nan"), -1.0, None, float("inf")])
def test_an_armature_that_is_not_a_finite_non_negative_number_is_one_input_error_naming_the_joint(value):
    with pytest.raises(robodyn.exceptions.InputError, match=r"armature\['joint1'\] must be a finite number >= 0"):
        robodyn.load("rp_arm", armature={"joint1": value})
