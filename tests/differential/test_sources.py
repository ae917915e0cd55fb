"""The reference given the same inputs as ``robodyn.load``: xacro arguments, package maps,
MJCF, the same robot as MJCF and as URDF, armature, damping and friction.

Every input that reaches ``robodyn.load`` reaches ``robodyn.reference.load`` here too (the
cases of :data:`tests.differential.cases.SOURCE_GENERATORS`: the xacro test arm with drawn
arguments — a prefix on every name, a link's mass, the finger and its mimic joint or not —
and its package map; the MJCF test files; each with drawn gravity, locks and armature),
and the two must agree on every quantity of ``robot_vs_reference`` and on each joint's
damping, friction and armature. A URDF and the MJCF MuJoCo writes of it (MuJoCo's own
converter, not robodyn's) must be one robot to both readers.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import robodyn
import robodyn.reference
from tests.differential import cases
from tests.differential.agree import PathsDisagreeError, agree, same
from tests.differential.cases import ROOT, SOURCE_GENERATORS, Case, draw_cases, draw_options, random_state_batch
from tests.differential.pairs import robot_vs_reference

pytestmark = pytest.mark.differential

FAST = draw_cases(2, base_seed=39, generators=tuple(SOURCE_GENERATORS))
SLOW = draw_cases(10, base_seed=390_000, generators=tuple(SOURCE_GENERATORS))


def rng_of(case: Case, name: str) -> np.random.Generator:
    return np.random.default_rng([case.seed, zlib.crc32(name.encode())])


def joint_dynamics(case: Case) -> None:
    """Each moving joint's damping, friction and armature: the Robot's (by dof name) are the
    reference's (its parsed joints), the drawn ``armature=`` added on top of the file's."""
    robot, reference = case.robot(), case.reference()
    joints = reference.spec.joints
    dofs = robot.dofs[6:] if robot.floating_base else robot.dofs
    for index, dof in enumerate(dofs, start=6 if robot.floating_base else 0):
        joint = joints[dof.joint]
        for quantity, ours, theirs in (
            ("damping", robot.joint_damping[index], joint.damping),
            ("friction", robot.joint_friction[index], joint.friction),
            ("armature", robot.joint_armature[index], joint.armature),
        ):
            agree(case, f"{quantity} of {dof.joint}", ours, theirs, rtol=1e-12, test="sources")


@pytest.mark.parametrize("case", FAST, ids=[case.id for case in FAST])
def test_the_reference_given_the_same_inputs_is_the_robot(case):
    robot_vs_reference(case, rng_of(case, "robot_vs_reference"))
    joint_dynamics(case)


@pytest.mark.slow
@pytest.mark.parametrize("case", SLOW, ids=[case.id for case in SLOW])
def test_the_reference_given_the_same_inputs_is_the_robot_on_the_sweep(case):
    robot_vs_reference(case, rng_of(case, "robot_vs_reference"))
    joint_dynamics(case)


def test_the_drawn_inputs_cover_what_the_reference_takes():
    """The fast cases draw xacro arguments other than the defaults, package maps, MJCF, and
    the armature option somewhere (else the checks above would not see them lost)."""
    drawn = [*FAST, *SLOW]
    assert any(case.options.get("xacro_args", {}).get("prefix") for case in FAST)
    assert any(case.options.get("packages") for case in FAST)
    assert {case.generator for case in FAST} == set(SOURCE_GENERATORS)
    assert any(case.options.get("armature") for case in drawn) and any(case.options.get("lock") for case in drawn)
    assert any(case.floating for case in drawn)


def test_a_reference_that_drops_the_xacro_arguments_is_caught(monkeypatch):
    """Negative control: the reference read with the package map but the default xacro
    arguments (another mass of the upper link) disagrees with the robot loaded with them."""
    arguments = {"prefix": "", "upper_mass": "2.5", "finger": "true"}  # the default mass is 1.3
    packages = {"robodyn_test_arm": str(cases.XACRO_PACKAGE)}
    case = Case("xacro_arm", 0, "negative control", cases.XACRO_ARM, {"xacro_args": arguments, "packages": packages})
    robot_vs_reference(case, rng_of(case, "robot_vs_reference"))  # given the arguments: one robot

    def without_arguments(case: Case):
        return robodyn.reference.load(case.source, packages=case.options["packages"])

    monkeypatch.setattr(cases, "_reference", without_arguments)
    with pytest.raises(PathsDisagreeError, match="tau"):
        robot_vs_reference(case, rng_of(case, "robot_vs_reference"))


# ----------------------------------------------------------------------------------------
# One robot written as URDF and as MJCF (by MuJoCo's converter)
# ----------------------------------------------------------------------------------------
mujoco = pytest.importorskip("mujoco")

#: URDFs MuJoCo writes back as MJCF robodyn reads (no <frame>: MuJoCo keeps fixed links as frames otherwise).
TWINS = ["rrp_arm.urdf", "gantry.urdf"]


def with_dynamics(text: str, rng: np.random.Generator) -> str:
    """A ``<dynamics damping friction>`` drawn for every moving joint (none there before)."""
    out = []
    for chunk in text.split("</joint>"):
        if 'type="fixed"' not in chunk and "<joint" in chunk:
            chunk += f'<dynamics damping="{rng.uniform(0.05, 0.5):.4f}" friction="{rng.uniform(0.01, 0.3):.4f}"/>'
        out.append(chunk)
    return "</joint>".join(out)


@pytest.mark.parametrize("name", TWINS)
def test_a_urdf_and_the_mjcf_mujoco_writes_of_it_are_one_robot(name, tmp_path):
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    urdf = with_dynamics((ROOT / "tests" / "data" / name).read_text(), rng)
    model = mujoco.MjModel.from_xml_string(urdf)
    mjcf = tmp_path / "twin.xml"
    mujoco.mj_saveLastXML(str(mjcf), model)
    options = draw_options(rng, urdf, floating=False)
    options.pop("threads")
    from_urdf = Case("twin", 0, f"{name} as URDF", urdf, options)
    from_mjcf = Case("twin", 0, f"{name} as MJCF (MuJoCo's)", mjcf, options)
    for case in (from_urdf, from_mjcf):  # each against its reference, with the same options
        robot_vs_reference(case, rng_of(case, "twin"))
        joint_dynamics(case)
    first, second = from_urdf.robot(), from_mjcf.robot()
    same(from_mjcf, "joint names", sorted(second.joint_names), sorted(first.joint_names), test="twin")
    order = [second.joint_names.index(joint) for joint in first.joint_names]
    q, v, a = random_state_batch(first, rng, 5)
    mapped = [np.empty_like(x) for x in (q, v, a)]
    for target, source in zip(mapped, (q, v, a), strict=True):
        target[:, order] = source
    agree(from_mjcf, "tau (MJCF vs URDF)", second.inverse_dynamics(*mapped)[:, order], first.inverse_dynamics(q, v, a))
    agree(from_mjcf, "M (MJCF vs URDF)", second.mass_matrix(mapped[0])[:, order][:, :, order], first.mass_matrix(q))
    for quantity in ("joint_damping", "joint_friction", "joint_armature"):
        agree(from_mjcf, quantity, getattr(second, quantity)[order], getattr(first, quantity), rtol=1e-12, test="twin")
    assert np.any(first.joint_damping > 0) and np.any(first.joint_friction > 0)  # the dynamics were there to lose
