"""Linearisation (robodyn.sim.linearize): continuous (A, B) from the derivatives, the exact
Jacobians of one simulator step against central differences of robodyn.simulate itself,
and against MuJoCo's mjd_transitionFD (semi-implicit Euler)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.sim.linearize import STEP_INTEGRATORS, actuation_matrix, linearization, linearize
from robodyn.sim.simulation import INTEGRATORS
from tests.conftest import NONDEGENERATE_CASES, random_states

GRAVITY = [0.8, 1.1, -9.3]


def load_case(name: str) -> robodyn.Robot:
    if name in NONDEGENERATE_CASES:
        path, options = NONDEGENERATE_CASES[name]
        return robodyn.load(path, gravity=GRAVITY, **options)
    return robodyn.load(name, gravity=GRAVITY)


def one_step(robot, q, v, tau, dt, integrator):
    """(q, v) after one step of robodyn.simulate with ``tau`` held."""
    run = robodyn.simulate(robot, q, v, dt, dt, controller=lambda t, q, v: tau, hold=True, integrator=integrator, limits="ignore")
    return run.q[-1], run.v[-1]


def difference(robot, q0, q1):
    """``q1 ⊖ q0`` in the tangent space at ``q0``."""
    return pin.difference(robot.model, q0, q1) if robot.floating_base else q1 - q0


def step_differences(robot, q, v, tau, dt, integrator, eps=1e-6):
    """Central differences of one simulator step: (A, B) with δq in the tangent space."""
    nv = robot.nv
    q_next, _ = one_step(robot, q, v, tau, dt, integrator)

    def state(qi, vi, taui):
        qn, vn = one_step(robot, qi, vi, taui, dt, integrator)
        return np.concatenate([difference(robot, q_next, qn), vn])

    A, B = np.zeros((2 * nv, 2 * nv)), np.zeros((2 * nv, nv))
    for j in range(nv):
        unit = np.eye(nv)[j] * eps
        A[:, j] = (state(robot.integrate(q, unit), v, tau) - state(robot.integrate(q, -unit), v, tau)) / (2 * eps)
        A[:, nv + j] = (state(q, v + unit, tau) - state(q, v - unit, tau)) / (2 * eps)
        B[:, j] = (state(q, v, tau + unit) - state(q, v, tau - unit)) / (2 * eps)
    return A, B


def relative(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def test_the_integrators_are_the_simulators():
    assert STEP_INTEGRATORS == INTEGRATORS


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
@pytest.mark.parametrize("name", ["gripper", "oblique_floating", "mimic_tree_floating", "double_pendulum_continuous"])
def test_one_step_matches_central_differences_of_the_simulator(name, integrator, rng):
    robot = load_case(name)
    q, v, tau = (x[0] for x in random_states(robot, rng, 1))
    dt = 0.02
    A, B = linearize(robot, q, v, tau, dt=dt, integrator=integrator)
    A_numeric, B_numeric = step_differences(robot, q, v, tau, dt, integrator)
    assert relative(A, A_numeric) < 1e-6, relative(A, A_numeric)
    assert relative(B, B_numeric) < 1e-6, relative(B, B_numeric)
    other = "rk4" if integrator != "rk4" else "semi-implicit-euler"  # negative control
    assert relative(linearize(robot, q, v, tau, dt=dt, integrator=other)[0], A_numeric) > 1e-5


@pytest.mark.parametrize("name", ["gripper", "oblique_floating"])
def test_continuous_time_is_the_limit_of_small_steps(name, rng):
    """(A_d − I) / dt → A_c: the floating base's −ad(v) block included (v ≠ 0 here)."""
    robot = load_case(name)
    q, v, tau = (x[0] for x in random_states(robot, rng, 1))
    A, B = linearize(robot, q, v, tau, joint_friction=False)  # the rigid-body derivatives themselves
    dq, dv, inverse = robot.forward_dynamics_derivatives(q, v, tau)
    nv = robot.nv
    np.testing.assert_array_equal(A[nv:, :nv], dq)
    np.testing.assert_array_equal(A[nv:, nv:], dv)
    np.testing.assert_array_equal(A[:nv, nv:], np.eye(nv))
    np.testing.assert_array_equal(B[nv:], inverse)
    dt = 1e-6
    A_d, B_d = linearize(robot, q, v, tau, dt=dt, integrator="rk4", joint_friction=False)
    assert relative(A, (A_d - np.eye(2 * nv)) / dt) < 1e-4
    assert relative(B, B_d / dt) < 1e-4
    if robot.floating_base:  # negative control: without the moving tangent space it fails
        naive = A.copy()
        naive[:6, :6] = 0.0
        assert relative(naive, (A_d - np.eye(2 * nv)) / dt) > 1e-3


def test_the_default_torque_holds_the_state_and_actuation_selects_columns(rng):
    robot = load_case("double_pendulum_continuous")
    q, v, _ = (x[0] for x in random_states(robot, rng, 1))
    result = linearization(robot, q, v, actuation=actuation_matrix(robot, [robot.joint_names[1]]))
    np.testing.assert_allclose(robot.forward_dynamics(q, v, result.tau), 0.0, atol=1e-9)
    full = linearize(robot, q, v)[1]
    np.testing.assert_array_equal(result.B, full[:, 1:])
    assert result.inputs == (robot.dofs[1].name,)
    document = result.to_dict()
    assert document["inputs"] == [robot.dofs[1].name] and len(document["A"]) == 2 * robot.nv
    assert "A:" in result.text()


@pytest.mark.parametrize(
    ("options", "argument"),
    [
        ({"dt": 0.0}, "dt"),
        ({"dt": float("nan")}, "dt"),
        ({"dt": True}, "dt"),
        ({"integrator": "euler"}, "integrator"),
        ({"actuation": np.ones((3, 1))}, "actuation"),
        ({"actuation": [["a", "b"]]}, "actuation"),
    ],
)
def test_bad_options_are_refused_naming_them(options, argument, rng):
    robot = load_case("double_pendulum_continuous")
    q, v, _ = (x[0] for x in random_states(robot, rng, 1))
    with pytest.raises(robodyn.InputError) as error:
        linearize(robot, q, v, **options)
    assert error.value.argument == argument


def test_a_linearization_of_a_batch_and_unknown_joints_are_refused(rng):
    """A Linearization is one state's (a batch goes to linearize, which stacks)."""
    robot = load_case("double_pendulum_continuous")
    q, v, _ = random_states(robot, rng, 2)
    with pytest.raises(robodyn.InputError, match="one state"):
        linearization(robot, q, v)
    with pytest.raises(robodyn.InputError) as error:
        actuation_matrix(robot, ["no_such_joint"])
    assert error.value.argument == "actuated"


# --------------------------------------------------------------------------------------
# MuJoCo's transition Jacobians: its Euler integrator is semi-implicit, like robodyn's
# --------------------------------------------------------------------------------------
mujoco = pytest.importorskip("mujoco")


def mujoco_with_motors(robot, dt):
    """MuJoCo's model of the URDF (contacts, limits, damping off) with a motor on every joint."""
    spec = mujoco.MjSpec.from_string(_urdf_for_mujoco(robot))
    for name in robot.joint_names:
        actuator = spec.add_actuator()
        actuator.name, actuator.target, actuator.trntype = f"motor_{name}", name, mujoco.mjtTrn.mjTRN_JOINT
    model = spec.compile()
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    model.opt.gravity[:] = robot.gravity_vector
    model.dof_damping[:] = model.dof_armature[:] = model.dof_frictionloss[:] = 0.0
    model.opt.timestep = dt
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    return model


def _urdf_for_mujoco(robot):
    import xml.etree.ElementTree as ET

    root = ET.fromstring(robot.urdf)
    for element in [*root.iter("link"), *root.iter("joint")]:
        for child in [c for c in element if c.tag in ("visual", "collision", "dynamics", "safety_controller", "calibration")]:
            element.remove(child)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", {"discardvisual": "true", "fusestatic": "false", "balanceinertia": "false"})
    return ET.tostring(root, encoding="unicode")


@pytest.mark.parametrize("name", ["ur5", "double_pendulum_continuous"])
def test_one_euler_step_matches_mujocos_transition_jacobians(name, rng):
    robot = load_case(name)
    dt = 2e-3
    model = mujoco_with_motors(robot, dt)
    data = mujoco.MjData(model)
    q, v, tau = (x[0] for x in random_states(robot, rng, 1))
    data.qpos[:], data.qvel[:], data.ctrl[:] = q, v, tau
    nv = robot.nv
    A_mj, B_mj = np.zeros((2 * nv, 2 * nv)), np.zeros((2 * nv, nv))
    mujoco.mjd_transitionFD(model, data, 1e-7, 1, A_mj, B_mj, None, None)
    # MuJoCo's model has no <dynamics> (its Euler step treats damping implicitly): rigid body
    A, B = linearize(robot, q, v, tau, dt=dt, integrator="semi-implicit-euler", joint_friction=False)
    assert relative(A, A_mj) < 1e-5, relative(A, A_mj)
    assert relative(B, B_mj) < 1e-5, relative(B, B_mj)
    rk4 = linearize(robot, q, v, tau, dt=dt, integrator="rk4", joint_friction=False)[0]
    assert relative(rk4, A_mj) > 10 * relative(A, A_mj)  # negative control: another integrator


def test_joint_damping_enters_the_linearisation_as_the_simulator_applies_it(rng):
    """The double pendulum's <dynamics damping>: ∂q̈/∂v gets −M⁻¹ diag(b), and one rk4 step's
    Jacobians match central differences of simulate with its default joint friction; the
    rigid-body linearisation (negative control) misses them."""
    robot = load_case("double_pendulum_continuous")
    assert robot.joint_damping.any()
    q, v, tau = (x[0] for x in random_states(robot, rng, 1))
    nv = robot.nv
    damped = linearize(robot, q, v, tau)[0]
    _, dv, inverse = robot.forward_dynamics_derivatives(q, v, tau - robot.joint_damping * v)
    np.testing.assert_allclose(damped[nv:, nv:], dv - inverse * robot.joint_damping, rtol=0, atol=1e-12)
    dt, h = 1e-3, 1e-6

    def step(x):
        run = robodyn.simulate(robot, x[:nv], x[nv:], dt, dt, controller=lambda t, q_, v_: tau, limits="ignore")
        return np.concatenate([run.q[-1], run.v[-1]])

    x = np.concatenate([q, v])
    differences = np.column_stack([(step(x + h * e) - step(x - h * e)) / (2 * h) for e in np.eye(2 * nv)])
    assert relative(linearize(robot, q, v, tau, dt=dt)[0], differences) < 1e-6
    assert relative(linearize(robot, q, v, tau, dt=dt, joint_friction=False)[0], differences) > 1e-5


def test_coulomb_friction_at_rest_is_refused_naming_the_way_out():
    robot = robodyn.load("z1")
    q = robot.default_configuration()
    with pytest.raises(robodyn.exceptions.InputError, match="joint_friction must be False to linearize at rest"):
        linearize(robot, q, np.zeros(robot.nv))
    A, _ = linearize(robot, q, np.zeros(robot.nv), joint_friction=False)
    assert np.isfinite(A).all()


def _count_derivative_calls(robot, monkeypatch) -> list[int]:
    """Rows of each call of the robot's forward-dynamics derivatives, recorded."""
    calls: list[int] = []
    original = robot.forward_dynamics_derivatives

    def counted(q, v, tau):
        calls.append(1 if np.ndim(q) == 1 else len(q))
        return original(q, v, tau)

    monkeypatch.setattr(robot, "forward_dynamics_derivatives", counted)
    return calls


@pytest.mark.parametrize("name", ["gripper", "oblique_floating", "z1"])
@pytest.mark.parametrize("count", [1, 7, 13])
def test_a_trajectory_linearizes_as_one_batch_each_row_its_single_call(name, count, rng, monkeypatch):
    """N states a row (N = 1, 7, 13: not multiples of the thread count) give stacks whose rows
    are their single calls bit for bit, continuous (one derivative call for the batch) and one
    RK4 / Euler step (one call a stage); a mimic gripper, a moving floating base, z1's Coulomb
    friction on moving joints, the holding torque of tau=None."""
    robot = load_case(name)
    q, v, tau = random_states(robot, rng, count)
    v = np.where(np.abs(v) < 0.05, 0.3, v)  # z1's joints slide (stiction is refused at rest)
    cases = [({}, 1), ({"dt": 2e-3, "integrator": "rk4"}, 4), ({"dt": 2e-3, "integrator": "semi-implicit-euler"}, 1)]
    for options, stages in cases:
        for torques in (tau, None) if not options else (tau,):
            calls = _count_derivative_calls(robot, monkeypatch)
            A, B = linearize(robot, q, v, torques, **options)
            assert calls == [count] * stages
            monkeypatch.undo()
            assert A.shape == (count, 2 * robot.nv, 2 * robot.nv) and B.shape == (count, 2 * robot.nv, robot.nv)
            for i in range(count):
                single = linearize(robot, q[i], v[i], None if torques is None else torques[i], **options)
                np.testing.assert_array_equal(A[i], single[0])
                np.testing.assert_array_equal(B[i], single[1])


def _continuous_differences(robot, q, v, tau, eps=1e-6):
    """Central differences of ``ẋ = (v, q̈(q, v, τ + friction))``, q along ``integrate``."""
    nv = robot.nv

    def rate(qi, vi, taui):
        from robodyn.dynamics.joint_dynamics import friction_torque

        return robot.forward_dynamics(qi, vi, taui + friction_torque(robot.joint_damping, robot.joint_friction, vi))

    A, B = np.zeros((2 * nv, 2 * nv)), np.zeros((2 * nv, nv))
    A[:nv, nv:] = np.eye(nv)
    for j in range(nv):
        unit = np.eye(nv)[j] * eps
        A[nv:, j] = (rate(robot.integrate(q, unit), v, tau) - rate(robot.integrate(q, -unit), v, tau)) / (2 * eps)
        A[nv:, nv + j] = (rate(q, v + unit, tau) - rate(q, v - unit, tau)) / (2 * eps)
        B[nv:, j] = (rate(q, v, tau + unit) - rate(q, v, tau - unit)) / (2 * eps)
    return A, B


def test_a_batchs_rows_match_central_differences_and_not_their_neighbours(rng):
    """The double pendulum with damping (the −M⁻¹ diag(b) term), 7 states: each row of the
    batch against central differences of forward dynamics at its own state; the rows shifted
    by one (negative control) do not match."""
    robot = load_case("double_pendulum_continuous")
    q, v, tau = random_states(robot, rng, 7)
    A, B = linearize(robot, q, v, tau)
    numeric = [_continuous_differences(robot, q[i], v[i], tau[i]) for i in range(7)]
    for i in range(7):
        assert relative(A[i, robot.nv :], numeric[i][0][robot.nv :]) < 1e-6
        assert relative(B[i], numeric[i][1]) < 1e-6
        assert relative(A[i, robot.nv :], numeric[(i + 1) % 7][0][robot.nv :]) > 1e-3


def test_a_bad_batch_is_refused_naming_the_argument(rng):
    """Rows that do not match, a 1-D v with a 2-D q, a NaN in one row; a Linearization (one
    state's names and units) refuses a batch."""
    robot = load_case("double_pendulum_continuous")
    q, v, tau = random_states(robot, rng, 5)
    bad_row = v.copy()
    bad_row[3, 1] = np.nan
    for arguments, name in [((q, v[:4], tau), "v"), ((q, v[0], tau), "v"), ((q, bad_row, tau), "v"), ((q, v, tau[:, :1]), "tau")]:
        with pytest.raises(robodyn.InputError) as error:
            linearize(robot, *arguments)
        assert error.value.argument == name
    with pytest.raises(robodyn.InputError, match="one state"):
        linearization(robot, q, v, tau)


@pytest.mark.parametrize("name", ["double_pendulum_continuous", "oblique_floating"])
def test_an_empty_batch_gives_empty_stacks(name):
    robot = load_case(name)
    q, v = np.zeros((0, robot.nq)), np.zeros((0, robot.nv))
    for options in ({}, {"dt": 1e-3}, {"dt": 1e-3, "integrator": "semi-implicit-euler"}):
        A, B = linearize(robot, q, v, **options)
        assert A.shape == (0, 2 * robot.nv, 2 * robot.nv) and B.shape == (0, 2 * robot.nv, robot.nv)
