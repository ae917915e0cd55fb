"""robodyn.dynamics.loading: one complete LoadOptions through load, rebuild and pickling (issue 23).

Issue 23 found that a robot loaded with ``max_dof=400`` could not be unpickled: the options
it travelled with lacked ``max_dof``, so the other side built it with the default limit.
A real 400-degree-of-freedom robot needs 4 GB of Pinocchio data, so these tests lower the
default limit instead (``MAX_DOF``) and load a small robot above it with ``max_dof=``.

Also here:

- Fuzzing the loader: mutated URDFs either load as a valid model or raise a robodyn error.

  Never another exception, never a silent non-finite model. The slow tier runs many more
  cases in a child process, so that a crash in native code would be reported, not fatal.

- robodyn.load: every kind of source, and clear errors for bad ones.
"""

from __future__ import annotations

import contextlib
import copy
import copyreg
import pickle
import re
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn
from robodyn import UnknownRobotError, URDFError
from robodyn.common.text import is_printable
from robodyn.dynamics import loading, options, pickling
from robodyn.dynamics.robot import Robot
from tests.conftest import ROOT, random_state

#: Every option of robodyn.load, none at its default, on panda: a mimic finger, and a floating base here.
EVERY_OPTION = {
    "floating_base": True,
    "gravity": (0.5, -1.0, -9.0),
    "check_inertia": False,
    "strict": True,
    "lock": {"panda_joint7": 0.2},
    "threads": 1,
    "max_dof": 40,
    "max_bytes": 10_000_000,
}


@pytest.fixture
def small_default_limit(monkeypatch):
    """A default max_dof below the robots' size (what 300 is to a 400-dof robot), and no robot
    already unpickled in this process (so unpickling builds under that default)."""
    monkeypatch.setattr(options, "MAX_DOF", 5)
    pickling.clear()
    yield
    pickling.clear()


def _assert_same_dynamics(copy_, robot, rng):
    q, v, a = random_state(robot, rng, 7)
    np.testing.assert_array_equal(copy_.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a))
    np.testing.assert_array_equal(copy_.mass_matrix(q), robot.mass_matrix(q))
    np.testing.assert_array_equal(copy_.coriolis_matrix(q, v), robot.coriolis_matrix(q, v))
    np.testing.assert_array_equal(copy_.forward_dynamics(q, v, a), robot.forward_dynamics(q, v, a))
    np.testing.assert_array_equal(copy_.frame_position(q, copy_.end_effector), robot.frame_position(q, robot.end_effector))


def test_the_options_record_every_option_load_takes():
    robot = robodyn.load("panda", **EVERY_OPTION)
    recorded = robot.options
    assert recorded.floating_base is True and recorded.gravity == (0.5, -1.0, -9.0)
    assert (recorded.check_inertia, recorded.strict, recorded.threads) == (False, True, 1)
    assert recorded.lock == (("panda_joint7", 0.2),) and recorded.max_dof == 40 and recorded.max_bytes == 10_000_000
    assert robot.mimic is not None and robot.floating_base and "panda_joint7" not in robot.joint_names


def test_a_robot_loaded_with_max_dof_survives_pickling(small_default_limit, rng):
    with pytest.raises(robodyn.URDFError, match="max_dof"):
        robodyn.load("ur5")  # negative control: the lowered default really refuses it
    robot = robodyn.load("ur5", max_dof=10)
    copy_ = pickle.loads(pickle.dumps(robot))
    assert copy_ is not robot and copy_.options == robot.options and copy_.options.max_dof == 10
    _assert_same_dynamics(copy_, robot, rng)


def test_a_robot_loaded_with_every_option_survives_pickling(small_default_limit, rng):
    robot = robodyn.load("panda", **EVERY_OPTION)
    before = pickling.builds
    copy_ = pickle.loads(pickle.dumps(robot))
    assert pickling.builds == before + 1 and copy_ is not robot
    assert copy_.options == robot.options and copy_.urdf == robot.urdf
    assert copy_.joint_names == robot.joint_names and copy_.threads == 1 and copy_.mimic is not None
    np.testing.assert_array_equal(copy_.gravity_vector, [0.5, -1.0, -9.0])
    _assert_same_dynamics(copy_, robot, rng)


def test_rebuild_and_a_payload_keep_every_option(small_default_limit, rng):
    robot = robodyn.load("panda", **EVERY_OPTION)
    copy_ = loading.rebuild(robot)
    assert copy_ is not robot and copy_.model is not robot.model and copy_.options == robot.options
    _assert_same_dynamics(copy_, robot, rng)
    carrying = robodyn.attach_payload(robot, "panda_hand", 0.5)
    assert carrying.options == robot.options and carrying.nv == robot.nv


def test_pickling_is_registered_with_copyreg_beside_the_loader():
    assert copyreg.dispatch_table[Robot] is loading._reduce
    robot = robodyn.load("rp_arm")
    function, arguments = copyreg.dispatch_table[Robot](robot)
    assert function is loading.restore and arguments == (robot.source, robot.options)


def test_copy_and_deepcopy_return_the_robot_itself_and_rebuild_an_independent_one():
    robot = robodyn.load("rp_arm", gravity=(0.0, 0.0, -1.0))
    assert copy.copy(robot) is robot and copy.deepcopy(robot) is robot
    holder = copy.deepcopy({"robot": robot, "gains": [1.0]})
    assert holder["robot"] is robot
    independent = loading.rebuild(robot)
    independent.model.gravity.linear = np.array([0.0, 0.0, -5.0])
    np.testing.assert_array_equal(robot.gravity_vector, [0.0, 0.0, -1.0])  # the original is untouched


SEEDS = [
    robodyn.rp_arm_urdf(),
    (ROOT / "tests" / "data" / "two_branches.urdf").read_text(),
    (ROOT / "tests" / "data" / "gantry.urdf").read_text(),
    robodyn.urdf.models.pendulum_urdf(3),
]
TOKENS = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e-308", "", "abc", "1 2", "1 2 3 4", "0 0 0", "  ", "1e-30", "3"]
# hostile spellings and names (issue #14): other parsers read these differently
TOKENS += [" 1.0 ", "1_000", "\uff12", "0x10", "1,5", "+.5", "\u00a01", "x\n robodyn: ok", "\x9b31m", "\u202eevil", "link1"]


def mutate(text: str, operations: list[tuple[int, int, int]]) -> str:
    """Apply mutations, each (kind, where, what) of small integers, to a URDF document."""
    for kind, where, what in operations:
        if kind == 0:  # truncate
            text = text[: where % max(len(text), 1)]
            continue
        try:
            root = ET.fromstring(text)
        except ET.ParseError:
            continue
        nodes = list(root.iter())
        node = nodes[where % len(nodes)]
        if kind == 1 and node.attrib:  # replace an attribute's value
            key = sorted(node.attrib)[what % len(node.attrib)]
            node.set(key, TOKENS[what % len(TOKENS)])
        elif kind == 2 and node is not root:  # delete an element
            for parent in root.iter():
                if node in list(parent):
                    parent.remove(node)
                    break
        elif kind == 3:  # duplicate an element under the root
            root.append(ET.fromstring(ET.tostring(node)))
        elif kind == 4 and node.tag == "joint":  # change a joint's type
            node.set("type", ["revolute", "continuous", "prismatic", "fixed", "floating", "planar", "screw"][what % 7])
        elif kind == 5 and node.attrib:  # rename an attribute
            key = sorted(node.attrib)[what % len(node.attrib)]
            node.set(key + "x", node.attrib.pop(key))
        text = ET.tostring(root, encoding="unicode")
    return text


def check_one(text: str) -> str:
    """Load a document; return "ok" or "refused", raise on anything else."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", robodyn.exceptions.RobodynWarning)
            robot = robodyn.load(text)
    except robodyn.RobodynError as error:
        assert is_printable(str(error)), repr(str(error))  # one printable line, whatever the input
        return "refused"
    q = robot.neutral_configuration()
    zeros = np.zeros(robot.nv)
    mass = robot.mass_matrix(q)
    assert np.isfinite(mass).all() and np.allclose(mass, mass.T)
    assert np.isfinite(robot.inverse_dynamics(q, zeros, zeros)).all()
    with contextlib.suppress(robodyn.SingularMassMatrixError):  # massless moving bodies
        assert np.isfinite(robot.forward_dynamics(q, zeros, zeros)).all()
    return "ok"


operations = st.lists(st.tuples(st.integers(0, 5), st.integers(0, 10_000), st.integers(0, 1000)), min_size=1, max_size=4)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(range(len(SEEDS))), operations)
def test_mutated_urdfs_load_or_are_refused_cleanly(seed, ops):
    check_one(mutate(SEEDS[seed], ops))


FUZZ_PROGRAM = """
import random, sys
sys.path.insert(0, {root!r})
from tests.dynamics.test_loading import SEEDS, check_one, mutate
rng = random.Random({seed})
outcomes = {{"ok": 0, "refused": 0}}
for case in range({count}):
    ops = [(rng.randrange(6), rng.randrange(10_000), rng.randrange(1000)) for _ in range(rng.randint(1, 5))]
    seed = rng.randrange(len(SEEDS))
    print("case", case, seed, ops, file=sys.stderr, flush=True)
    outcomes[check_one(mutate(SEEDS[seed], ops))] += 1
print(outcomes["ok"], outcomes["refused"])
"""


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_many_mutations_in_a_child_process(seed):
    program = FUZZ_PROGRAM.format(root=str(ROOT), seed=seed, count=1500)
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=600, cwd=ROOT)
    last_case = result.stderr.strip().splitlines()[-1] if result.stderr.strip() else ""
    assert result.returncode == 0, f"child died with {result.returncode} at {last_case}: {result.stderr[-2000:]}"
    ok, refused = map(int, result.stdout.split())
    assert ok + refused == 1500 and ok > 0 and refused > 0


RP_PATH = ROOT / "urdf" / "rp_arm.urdf"


def test_every_source_kind_gives_the_same_robot():
    robots = [robodyn.load("rp_arm"), robodyn.load(str(RP_PATH)), robodyn.load(RP_PATH), robodyn.load(RP_PATH.read_text())]
    q = [0.4, 0.1]
    for robot in robots:
        assert robot.joint_names == ["joint1", "joint2"]
        np.testing.assert_allclose(robot.mass_matrix(q), robots[0].mass_matrix(q))


def test_generated_robot_keeps_its_urdf_text():
    assert robodyn.load("rp_arm").urdf == robodyn.rp_arm_urdf()


def test_zoo_robot_resolves_package_paths():
    robot = robodyn.load("panda")
    assert robot.nq == robot.nv == 8  # seven arm joints and one finger; the other finger mimics it
    assert robot.package_dirs and all(Path(d).is_dir() for d in robot.package_dirs)
    mesh = robot.spec.xml.find(".//mesh").get("filename")
    assert mesh.startswith("package://")
    relative = mesh.removeprefix("package://")
    assert any((Path(d) / relative).is_file() for d in robot.package_dirs)


def test_continuous_joints_take_one_angle_each():
    robot = robodyn.load("double_pendulum_continuous")
    assert [joint.type for joint in robot.joints] == ["continuous", "continuous"]
    assert robot.nq == robot.nv == 2
    # An angle and the same angle plus a full turn are the same configuration.
    q = np.array([0.3, -1.1])
    np.testing.assert_allclose(robot.mass_matrix(q), robot.mass_matrix(q + 2 * np.pi), atol=1e-12)


def test_mimic_joint_follows_its_source():
    robot = robodyn.load("panda")
    assert "panda_finger_joint2" not in robot.joint_names
    q = robot.neutral_configuration()
    q[-1] = 0.03
    left = robot.frame_position(q, "panda_leftfinger")
    right = robot.frame_position(q, "panda_rightfinger")
    assert np.linalg.norm(left - right) == pytest.approx(0.06, abs=1e-9)


def test_joints_are_ordered_by_name_not_by_position_in_the_file():
    text = RP_PATH.read_text()
    joint2 = text[text.index('  <joint name="joint2"') : text.index("  </joint>", text.index('<joint name="joint2"')) + 11]
    reordered = text.replace(joint2, "").replace("</robot>", joint2 + "</robot>")
    robot = robodyn.load(reordered)
    assert robot.joint_names == ["joint1", "joint2"]
    np.testing.assert_allclose(robot.gravity([0.2, 0.1]), robodyn.load("rp_arm").gravity([0.2, 0.1]))


def test_floating_base_from_the_zoo():
    robot = robodyn.load("solo12")
    assert robot.floating_base and robot.nq == robot.nv + 1 == 19
    assert robodyn.load("solo12", floating_base=False).nq == 12


def test_gravity_option():
    robot = robodyn.load("rp_arm", gravity=[0, 0, -1.62])
    assert robot.gravity([0.0, 0.0])[0] == pytest.approx(robodyn.load("rp_arm").gravity([0.0, 0.0])[0] * 1.62 / 9.81)


def test_unknown_name_suggests_close_names():
    with pytest.raises(UnknownRobotError, match="did you mean panda"):
        robodyn.load("pandaa")


def test_missing_file_is_a_urdf_error(tmp_path):
    with pytest.raises(URDFError, match="no such file"):
        robodyn.load(tmp_path / "missing.urdf")


def test_malformed_xml_is_a_urdf_error():
    with pytest.raises(URDFError, match="not well-formed XML"):
        robodyn.load("<robot name='x'><link name='a'></robot>")


def test_negative_mass_names_the_link():
    text = robodyn.rp_arm_urdf().replace('<mass value="1.0"/>', '<mass value="-1.0"/>')
    with pytest.raises(URDFError, match=re.escape('link "link2": mass -1.0 kg must not be negative')):
        robodyn.load(text)


def test_robot_names_list_generated_and_zoo():
    names = robodyn.robot_names()
    assert names[:2] == ["pendulum", "rp_arm"]
    assert {"panda", "ur5", "double_pendulum", "solo12"} <= set(names)


def _branch(name: str, child: str, extra: str = "", parent: str = "base") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0.1 0.2 0" rpy="0 0.3 0"/><axis xyz="0 0.6 0.8"/>'
        f'<limit lower="-2" upper="2" effort="5" velocity="1"/>{extra}</joint>'
        f'<link name="{child}"><inertial><origin xyz="0.3 0 0"/><mass value="0.7"/>'
        f'<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>'
    )


def test_a_mimic_met_before_its_source_loads_and_matches_the_reference():
    """Pinocchio refuses a mimic joint whose subtree it meets before its source's (romeo,
    talos_full): robodyn orders the source's subtree first and keeps every name."""
    from robodyn import reference

    text = (
        '<robot name="gripper"><link name="base"/>'
        + _branch("a_finger", "finger", '<mimic joint="z_motor" multiplier="-0.7" offset="0.1"/>')
        + _branch("m_wrist", "wrist")
        + _branch("z_motor", "motor", parent="wrist")
        + '<link name="j0000000"/><joint name="tip" type="fixed"><parent link="finger"/><child link="j0000000"/></joint>'
        + "</robot>"
    )
    import pinocchio as pin

    with pytest.raises((RuntimeError, ValueError)):  # negative control: Pinocchio alone refuses it
        pin.buildModelFromXML(text, mimic=True)
    robot = robodyn.load(text)
    assert sorted(robot.joint_names) == ["m_wrist", "z_motor"]
    assert "j0000000" in robot.frame_names and "tip" in robot.frame_names and "a_finger" in robot.frame_names
    twin = reference.load(text)
    rng = np.random.default_rng(3)
    q, v, a = rng.uniform(-1, 1, (3, 2))
    assert sorted(twin.joint_names) == sorted(robot.joint_names)
    order = [robot.joint_names.index(name) for name in twin.joint_names]
    np.testing.assert_allclose(
        robot.inverse_dynamics(q, v, a)[order], twin.inverse_dynamics(q[order], v[order], a[order]), rtol=1e-10, atol=1e-12
    )
    # the mimic relation holds: the finger frame follows -0.7 q_motor + 0.1
    finger = robot.frame_position(q, "finger")
    unlocked = robodyn.load(text.replace('<mimic joint="z_motor" multiplier="-0.7" offset="0.1"/>', ""))
    q_full = np.zeros(3)
    names = unlocked.joint_names
    q_full[names.index("m_wrist")] = q[robot.joint_names.index("m_wrist")]
    q_full[names.index("z_motor")] = q[robot.joint_names.index("z_motor")]
    q_full[names.index("a_finger")] = -0.7 * q[robot.joint_names.index("z_motor")] + 0.1
    np.testing.assert_allclose(unlocked.frame_position(q_full, "finger"), finger, atol=1e-14)


@st.composite
def trees_with_a_mimic(draw):
    """A random tree of revolute joints in which one joint mimics another that is not
    below it; joint names are random, so Pinocchio's name order is any order."""
    count = draw(st.integers(3, 6))
    names = draw(st.lists(st.text("abcdefgxyz", min_size=1, max_size=3), min_size=count, max_size=count, unique=True))
    parents = [draw(st.integers(0, i)) for i in range(count)]  # joint i hangs below link parents[i]
    below = {i: {i} for i in range(count)}
    for i in reversed(range(count)):
        if parents[i] > 0:
            below[parents[i] - 1] |= below[i]
    mimic = draw(st.sampled_from([i for i in range(count) if len(below[i]) < count]))
    source = draw(st.sampled_from([i for i in range(count) if i not in below[mimic]]))
    multiplier = draw(st.sampled_from([-0.7, 0.5, 1.3]))
    parts = ['<robot name="tree"><link name="l0"/>']
    for i in range(count):
        extra = f'<mimic joint="{names[source]}" multiplier="{multiplier}" offset="0.05"/>' if i == mimic else ""
        parts.append(_branch(names[i], f"l{i + 1}", extra, parent=f"l{parents[i]}"))
    return "".join([*parts, "</robot>"])


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees_with_a_mimic())
def test_any_mimic_order_loads_and_matches_the_reference(text):
    from robodyn import reference

    robot = robodyn.load(text)
    twin = reference.load(text)
    order = [robot.joint_names.index(name) for name in twin.joint_names]
    q, v, a = np.random.default_rng(0).uniform(-1, 1, (3, robot.nv))
    np.testing.assert_allclose(
        robot.inverse_dynamics(q, v, a)[order], twin.inverse_dynamics(q[order], v[order], a[order]), rtol=1e-9, atol=1e-12
    )
