"""robodyn.compiled on floating bases (Pinocchio's free flyer) against Pinocchio and the reference."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.compiled import compile
from robodyn.exceptions import CompileError, SingularMassMatrixError
from robodyn.reference import load as load_reference
from robodyn.urdf.zoo import ZOO
from tests.compiled_helpers import compare, relative_error, shared_cache

#: A floating tree written here: an oblique revolute and an oblique prismatic joint on one
#: branch, a mimic joint (multiplier -1.3, offset 0.2) and a joint with armature on the other.
FLOATING_TREE = """<robot name="floating_tree">
  <link name="base"><inertial><origin xyz="0.05 -0.02 0.03" rpy="0.1 0.2 -0.3"/><mass value="3.0"/>
    <inertia ixx="0.05" ixy="0.004" ixz="-0.003" iyy="0.07" iyz="0.002" izz="0.09"/></inertial></link>
  <link name="l1"><inertial><origin xyz="0.1 0.02 -0.05"/><mass value="1.1"/>
    <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.012" iyz="-0.002" izz="0.008"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.0 0.07 0.02"/><mass value="0.6"/>
    <inertia ixx="0.004" ixy="0" ixz="0.0005" iyy="0.003" iyz="0" izz="0.005"/></inertial></link>
  <link name="l3"><inertial><origin xyz="-0.03 0.0 0.09"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0" iyy="0.007" iyz="0.001" izz="0.004"/></inertial></link>
  <link name="l4"><inertial><origin xyz="0.02 0.04 0.0"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0.2 0.1 -0.05" rpy="0.3 -0.2 0.5"/><axis xyz="0.3 -0.5 0.8"/>
    <limit lower="-2" upper="2" effort="50" velocity="5"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.15 0 0.02" rpy="0 0.4 0"/><axis xyz="0.6 0.2 -0.4"/>
    <limit lower="-0.2" upper="0.2" effort="50" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="base"/><child link="l3"/>
    <origin xyz="-0.2 0.05 0.1" rpy="-0.2 0 0.7"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="50" velocity="5"/><mimic joint="j1" multiplier="-1.3" offset="0.2"/></joint>
  <joint name="j4" type="continuous"><parent link="l3"/><child link="l4"/>
    <origin xyz="0 0 0.2" rpy="0.1 0.1 0.1"/><axis xyz="1 0 0"/></joint>
</robot>
"""
GRAVITY = (1.2, -0.7, -9.3)
QUANTITIES = ("inverse_dynamics", "mass_matrix", "nonlinear_effects", "gravity", "forward_dynamics")


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


def _tree_robot() -> robodyn.Robot:
    return robodyn.load(FLOATING_TREE, floating_base=True, gravity=GRAVITY, armature={"j4": 0.02})


@pytest.fixture(scope="module")
def tree():
    robot = _tree_robot()
    return robot, compile(robot)


def _states(robot, rng: np.random.Generator, count: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random states with random orientations (a normalised Gaussian quaternion) and base positions."""
    q = np.atleast_2d(robot.random_configuration(rng, count)).copy()
    quaternion = rng.normal(size=(len(q), 4))
    q[:, 3:7] = quaternion / np.linalg.norm(quaternion, axis=1, keepdims=True)
    q[:, :3] = rng.normal(size=(len(q), 3))
    shape = (robot.nv,) if count is None else (count, robot.nv)
    return (q[0] if count is None else q), rng.normal(size=shape), rng.normal(size=shape)


def _pinocchio(robot, name: str, q, v, a):
    """Pinocchio's free-flyer model itself (not through robodyn), one state."""
    model, data = robot.model, robot.model.createData()
    if name == "inverse_dynamics":
        return pin.rnea(model, data, q, v, a)
    if name == "mass_matrix":
        return robot.mass_matrix(q)  # the mimic map is robodyn's; checked against crba below without mimic
    if name == "nonlinear_effects":
        return pin.nonLinearEffects(model, data, q, v)
    if name == "gravity":
        return pin.computeGeneralizedGravity(model, data, q)
    return pin.aba(model, data, q, v, a)


def _call(compiled, name: str, q, v, a):
    arguments = {"mass_matrix": (q,), "gravity": (q,), "nonlinear_effects": (q, v)}.get(name, (q, v, a))
    return getattr(compiled, name)(*arguments)


def test_the_floating_tree_is_nondegenerate(tree):
    robot, compiled = tree
    assert robot.floating_base and robot.mimic is not None and (robot.nq, robot.nv) == (10, 9)
    assert compiled.nv == 9 and compiled.nq == 10
    assert compiled.module.info()["parents"][:7] == (-1, 0, 1, 2, 3, 4, 5)


@pytest.mark.parametrize("count", [None, 7, 129])
def test_a_floating_tree_matches_the_robot_one_state_and_batches(tree, rng, count):
    robot, compiled = tree
    q, v, a = _states(robot, rng, count)
    tau = robot.inverse_dynamics(q, v, a)
    for name in QUANTITIES:
        ours = _call(compiled, name, q, v, tau if name == "forward_dynamics" else a)
        theirs = _call(robot, name, q, v, tau if name == "forward_dynamics" else a)
        assert relative_error(ours, theirs) < 1e-12, name
    compare(compiled, robot, rng, count=count)


@pytest.mark.slow
def test_solo12_matches_pinocchios_free_flyer_itself(rng):
    robot = robodyn.load("solo12")
    compiled = compile(robot)
    assert robot.mimic is None
    for q, v, a in zip(*_states(robot, rng, 7), strict=True):
        for name in QUANTITIES:
            theirs = _pinocchio(robot, name, q, v, a)
            if name == "mass_matrix":
                theirs = pin.crba(robot.model, robot.model.createData(), q)
                theirs = np.triu(theirs) + np.triu(theirs, 1).T
            assert relative_error(_call(compiled, name, q, v, a), theirs) < 1e-12, name


def _reference_order(robot, reference) -> tuple[np.ndarray, np.ndarray]:
    """Index arrays: the reference's ``q`` and ``v`` entries in the robot's order (joints by name)."""
    joints = [reference.joint_names.index(name) - 1 for name in robot.joint_names[1:]]
    return np.array([*range(7), *(7 + j for j in joints)]), np.array([*range(6), *(6 + j for j in joints)])


def test_a_floating_tree_matches_the_reference(tree, rng):
    robot, compiled = tree
    reference = load_reference(FLOATING_TREE, floating_base=True, gravity=GRAVITY, armature={"j4": 0.02})
    iq, iv = _reference_order(robot, reference)
    q, v, a = _states(robot, rng, 7)
    Q, V, A = np.empty_like(q), np.empty_like(v), np.empty_like(a)
    Q[:, iq], V[:, iv], A[:, iv] = q, v, a
    expected = {
        "inverse_dynamics": reference.inverse_dynamics(Q, V, A)[:, iv],
        "mass_matrix": reference.mass_matrix(Q)[:, iv][:, :, iv],
        "nonlinear_effects": reference.nonlinear_effects(Q, V)[:, iv],
        "gravity": reference.gravity(Q)[:, iv],
        "forward_dynamics": reference.forward_dynamics(Q, V, A)[:, iv],
    }
    for name, theirs in expected.items():
        assert relative_error(_call(compiled, name, q, v, a), theirs) < 1e-9, name


def test_negative_controls_another_quaternion_order_or_velocity_frame_fails_the_check(tree, rng):
    """``w x y z`` instead of ``x y z w``, or the base velocity in world axes instead of the
    base's: the comparison must notice (else it checks no convention)."""
    robot, compiled = tree
    q, v, a = _states(robot, rng)
    expected = robot.inverse_dynamics(q, v, a)
    assert relative_error(compiled.inverse_dynamics(q, v, a), expected) < 1e-12
    swapped = q.copy()
    swapped[3:7] = np.roll(q[3:7], 1)
    assert relative_error(compiled.inverse_dynamics(swapped, v, a), expected) > 1e-3
    rotation = pin.Quaternion(q[6], *q[3:6]).toRotationMatrix()
    world = v.copy()
    world[:3], world[3:6] = rotation @ v[:3], rotation @ v[3:6]
    assert relative_error(compiled.inverse_dynamics(q, world, a), expected) > 1e-3


def test_derivatives_and_frame_kinematics_of_a_floating_base_are_refused_in_one_line(tree):
    robot, compiled = tree
    q, v = robot.neutral_configuration(), np.zeros(robot.nv)
    with pytest.raises(CompileError, match="floating base") as error:
        compiled.inverse_dynamics_derivatives(q, v, v)
    assert "\n" not in str(error.value)
    with pytest.raises(CompileError, match="floating base"):
        compiled.frame_position(q, "l4")


def _tree_at(gravity) -> robodyn.Robot:
    return robodyn.load(FLOATING_TREE, floating_base=True, gravity=gravity, armature={"j4": 0.02})


def _both_engines(robot, q0, v0, duration, dt, **options):
    """The same run in C and on the Pinocchio engine (Python, pinocchio.integrate on SE(3))."""
    runs = [
        robodyn.simulate(robot, q0, v0, duration, dt, engine=engine, limits="ignore", **options)
        for engine in ("compiled", "pinocchio")
    ]
    return runs


def _energy_drift(robot, run) -> float:
    energy = robot.kinetic_energy(run.q, run.v) + robot.potential_energy(run.q)
    return float(np.abs(energy - energy[0]).max() / abs(energy[0]))


def _spinning_state(robot, rng):
    q0 = robot.random_configuration(rng)
    quaternion = rng.normal(size=4)
    q0[3:7] = quaternion / np.linalg.norm(quaternion)
    return q0, 3.0 * rng.normal(size=robot.nv)  # the base turns by ~5e-3 rad a step


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_the_c_loop_follows_the_python_engine_on_se3(integrator, rng):
    robot = _tree_at(GRAVITY)
    q0, v0 = _spinning_state(robot, rng)
    compiled, python = _both_engines(robot, q0, v0, 0.5, 1e-3, integrator=integrator)
    assert compiled.q.shape == (501, robot.nq)
    assert np.abs(compiled.q[:, 3:7] - q0[3:7]).max() > 0.1  # the base turned
    for name in ("q", "v", "a"):
        assert relative_error(getattr(compiled, name), getattr(python, name)) < 1e-9, name
    # nearly still in orientation (the series branch of exp6): free fall, joints at rest
    slow = np.zeros(robot.nv)
    slow[:6] = [1.0, 0.5, 0.0, 0.01, -0.02, 0.005]
    compiled, python = _both_engines(robot, q0, slow, 0.2, 1e-3, integrator=integrator)
    assert relative_error(compiled.q, python.q) < 1e-9 and relative_error(compiled.v, python.v) < 1e-9


@pytest.mark.slow
def test_a_passive_floating_robot_keeps_its_energy_in_both_engines(rng):
    """Gravity off: RK4 conserves energy to its fourth order; gravity on: to second order (the
    base's orientation, no dexp correction, as robodyn.simulate documents). Negative control:
    semi-implicit Euler's first-order energy error is seen."""
    drifts = {}
    for label, gravity in (("off", (0.0, 0.0, 0.0)), ("on", GRAVITY)):
        robot = _tree_at(gravity)
        q0, v0 = _spinning_state(robot, np.random.default_rng(5))
        for dt in (2e-3, 1e-3):
            compiled, python = _both_engines(robot, q0, v0, 0.3, dt)
            assert relative_error(compiled.q, python.q) < 1e-9
            drifts[label, dt] = _energy_drift(robot, compiled)
            assert drifts[label, dt] == pytest.approx(_energy_drift(robot, python), rel=1e-3, abs=1e-12)
        euler = robodyn.simulate(robot, q0, v0, 0.3, 1e-3, engine="compiled", integrator="semi-implicit-euler", limits="ignore")
        assert _energy_drift(robot, euler) > 1e-4
    assert drifts["off", 2e-3] < 1e-10
    assert drifts["on", 1e-3] < 1e-5 and drifts["on", 2e-3] / drifts["on", 1e-3] > 3.0


def test_pd_and_computed_torque_drive_a_floating_robots_joints_in_c_as_in_python(rng):
    from robodyn.sim.control import ComputedTorque, PDGravity, quintic_reference
    from robodyn.sim.simulation import simulate_run

    robot = _tree_at(GRAVITY)
    q0, v0 = robot.random_configuration(rng), rng.normal(size=robot.nv)
    target = q0[7:] + 0.3
    laws = (PDGravity(robot, target, 50.0, 5.0), ComputedTorque(robot, quintic_reference(q0[7:], target, 0.3), 100.0, 20.0))
    for law in laws:
        compiled, run = simulate_run(robot, q0, v0, 0.6, 1e-3, controller=law, engine="compiled", limits="ignore")
        assert run.engine == "compiled" and run.controller_in_c, run
        python = robodyn.simulate(robot, q0, v0, 0.6, 1e-3, controller=law, engine="pinocchio", limits="ignore")
        for name in ("q", "v", "tau"):
            assert relative_error(getattr(compiled, name), getattr(python, name)) < 1e-9, (type(law).__name__, name)
        assert np.abs(compiled.tau[:, :6]).max() == 0.0  # the base is free
    assert np.abs(compiled.q[-1, 7:] - target).max() < 5e-3  # computed torque brought the joints to the target


FLOATING_ZOO = sorted(name for name, entry in ZOO.items() if entry.floating_base)


@pytest.mark.slow
@pytest.mark.parametrize("name", FLOATING_ZOO)
def test_every_floating_zoo_robot_compiles_and_matches_the_robot(name, rng):
    try:
        robot = robodyn.load(name)
    except robodyn.RobodynError as error:  # a zoo file this install cannot read: not ours to compile
        pytest.skip(str(error))
    compiled = compile(robot)
    if robot.massless_joints:  # romeo's hands move no mass: forward dynamics refused alike
        q, v, a = _states(robot, rng, 7)
        for name in QUANTITIES[:-1]:
            assert relative_error(_call(compiled, name, q, v, a), _call(robot, name, q, v, a)) < 1e-9, name
        for model in (robot, compiled):
            with pytest.raises(SingularMassMatrixError):
                model.forward_dynamics(q, v, a)
        return
    for count in (None, 7, 129):
        compare(compiled, robot, rng, count=count, rtol=1e-9)
    q, v, a = _states(robot, rng, 7)
    assert relative_error(compiled.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a)) < 1e-9


@pytest.mark.slow
def test_solo12_runs_in_c_as_in_python_passive_and_under_pd(rng):
    from robodyn.sim.control import PDGravity

    robot = robodyn.load("solo12")
    q0 = robot.floating_configuration([0.0, 0.0, 0.5], [0.2, -0.1, 0.4], robot.neutral_configuration()[7:] + 0.2)
    v0 = rng.normal(size=robot.nv)
    for controller in (None, PDGravity(robot, robot.neutral_configuration()[7:], 5.0, 0.2)):
        compiled, python = _both_engines(robot, q0, v0, 0.3, 1e-3, controller=controller)
        for name in ("q", "v", "tau"):
            assert relative_error(getattr(compiled, name), getattr(python, name)) < 1e-9, name


def test_a_quaternion_that_is_not_unit_is_refused_like_the_robot(tree):
    """The fast path (straight to C) must not compute with a non-unit quaternion that the
    robot refuses: same InputError, one state and a batch."""
    robot, compiled = tree
    q, v = robot.neutral_configuration(), np.zeros(robot.nv)
    q[3:7] = [0.3, 0.2, 0.1, 2.0]
    for call in (lambda q: robot.inverse_dynamics(q, v, v), lambda q: compiled.inverse_dynamics(q, v, v)):
        with pytest.raises(robodyn.InputError, match="unit quaternion"):
            call(q)
    with pytest.raises(robodyn.InputError, match="unit quaternion"):
        compiled.mass_matrix(np.tile(q, (7, 1)))
    q[3:7] /= np.linalg.norm(q[3:7])
    assert relative_error(compiled.gravity(q), robot.gravity(q)) < 1e-12
