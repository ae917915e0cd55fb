"""The fast contact step (:class:`robodyn.sim.contact.ContactStepper`) against the general one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.compiled import build
from robodyn.compiled import contact as compiled_contact
from robodyn.exceptions import CompilerNotFoundError, SingularMassMatrixError
from robodyn.sim import contact
from robodyn.sim.contact import ContactSettings, ContactStepper, contact_kinematics, contact_step, generic_step
from robodyn.sim.ground import ContactPoint, Ground, contact_points

DATA = Path(__file__).parents[1] / "data" / "contact"
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def solo() -> robodyn.Robot:
    return robodyn.load("solo12")


@pytest.fixture(scope="module")
def box() -> robodyn.Robot:
    return robodyn.load(DATA / "box.urdf", floating_base=True)


def _both(robot, q, v, controller, ground, points, steps):
    """Per step, the fast and the general step's (q⁺, v⁺, forces), each on its own run."""
    settings, runs = ContactSettings(), []
    for fast in (True, False):
        state, guess, rows = (q, v), None, []
        for _ in range(steps):
            tau = controller(state[0], state[1])
            if fast:
                result = contact_step(robot, *state, tau, 1e-3, ground, points, settings=settings, guess=guess)
            else:
                result = generic_step(robot, *state, tau, 1e-3, ground, points, settings, guess)
            rows.append((result.q, result.v, result.forces, result.iterations))
            state, guess = (result.q, result.v), result.impulses
        runs.append(rows)
    return runs


def _largest_difference(runs, index):
    return max(float(np.abs(a[index] - b[index]).max()) for a, b in zip(*runs, strict=True))


@pytest.mark.parametrize(("friction", "push"), [(0.8, 0.0), (0.2, 0.5)])
def test_solo12_landing_on_its_feet_is_the_general_steps_motion(solo, friction, push):
    """Standing (μ = 0.8) and landing while sliding and turning (μ = 0.2: slipping modes):
    the same ADMM iterations every step; the motions part only by ADMM's own tolerance
    (1e-10) acting on round-off (measured: v⁺ 7e-12 / 1e-9 m/s, forces 3e-10 / 4e-8 N)."""
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), 1e-4) for foot in FEET)
    ground = Ground(height=0.01, friction=friction)  # a raised floor: its level counts
    q0 = solo.neutral_configuration()
    q0[7:] += np.linspace(-0.2, 0.2, 12)  # legs apart from the neutral pose: every mask matters
    q0[2] += -contact_kinematics(solo, q0, ground, points)[0].min() + 0.005
    v0 = np.zeros(solo.nv)
    v0[[0, 1, 5]] = (push, 0.6 * push, 0.8 * push)
    target = q0[7:].copy()

    def hold(q, v):
        tau = np.zeros(solo.nv)
        tau[6:] = 5.0 * (target - q[7:]) - 0.1 * v[6:]
        return tau

    runs = _both(solo, q0, v0, hold, ground, points, 150)
    assert any(row[3] > 0 for row in runs[0]) and any(row[3] == 0 for row in runs[0])  # ADMM, and modes kept
    assert [row[3] for row in runs[0]] == [row[3] for row in runs[1]]
    assert _largest_difference(runs, 2) < 1e-8 * solo.total_mass * 9.81  # forces, [N]
    assert _largest_difference(runs, 1) < 1e-8  # v⁺ [m/s, rad/s]
    assert _largest_difference(runs, 0) < 1e-11  # q⁺


def test_the_steppers_jacobian_is_the_frame_jacobians_and_a_point_seeing_every_joint_is_not(solo):
    points = (*contact_points(solo, list(FEET)).points, ContactPoint("knee", "FR_LOWER_LEG", (0.01, -0.02, 0.03), 0.02))
    ground = Ground.tilted(0.3, friction=0.5, height=-0.1)
    q = solo.random_configuration(np.random.default_rng(7))
    stepper = ContactStepper(solo, ground, points)
    gaps, jacobian = contact_kinematics(solo, q, ground, points)
    fast_gaps, fast_jacobian = stepper.kinematics(q)
    assert np.abs(fast_gaps - gaps).max() < 1e-15 and np.abs(fast_jacobian - jacobian).max() < 1e-14
    stepper.mask[:] = 1.0  # negative control: every column to every point
    assert np.abs(stepper.kinematics(q)[1] - jacobian).max() > 1e-2


def test_a_run_keeps_its_stepper_and_a_first_step_or_new_points_make_a_new_one(box):
    ground, points = Ground(friction=0.5), contact_points(box, "collision").points
    q, v, tau = box.neutral_configuration(), np.zeros(box.nv), np.zeros(box.nv)
    q[2] = 0.06
    first = contact_step(box, q, v, tau, 1e-3, ground, points)
    stepper = contact._LOCAL.stepper
    contact_step(box, first.q, first.v, tau, 1e-3, ground, points, guess=first.impulses)
    assert contact._LOCAL.stepper is stepper
    contact_step(box, first.q, first.v, tau, 1e-3, ground, points[:4], guess=first.impulses[:4])
    assert contact._LOCAL.stepper is not stepper
    stepper = contact._LOCAL.stepper
    contact_step(box, first.q, first.v, tau, 1e-3, ground, points[:4])
    assert contact._LOCAL.stepper is not stepper  # guess=None: a run's first step, built again


def test_pinocchios_inverse_is_the_inverse_of_robodyns_mass_matrix_armature_included(solo):
    """The stepper's ``M⁻¹`` (``computeMinverse``'s upper triangle) against ``Robot.mass_matrix``,
    and on a model with armature against CRBA's ``M``, which adds it."""
    q = solo.random_configuration(np.random.default_rng(5))
    stepper = ContactStepper(solo, Ground(), ())
    inverse = pin.computeMinverse(stepper.model, stepper.data, q)
    np.copyto(inverse, inverse.T, where=stepper.lower)
    assert np.abs(inverse @ solo.mass_matrix(q) - np.eye(solo.nv)).max() < 1e-12
    model = solo.model.copy()
    model.armature[6:] = np.linspace(0.01, 0.1, 12)
    data = model.createData()
    mass, inverse = pin.crba(model, data, q).copy(), pin.computeMinverse(model, data, q).copy()
    mass, inverse = np.triu(mass) + np.triu(mass, 1).T, np.triu(inverse) + np.triu(inverse, 1).T
    assert np.abs(inverse @ mass - np.eye(solo.nv)).max() < 1e-12
    assert np.abs(inverse @ solo.mass_matrix(q) - np.eye(solo.nv)).max() > 1e-3  # the armature counts


def _c_against_numpy(robot, ground, points, q, controller, settle, steps):
    """``settle`` steps (numpy alone), then ``steps`` steps: at each, the C step
    (robodyn/compiled/contact.c) and numpy's polish from the same state; the run goes on
    from the C step's. Every one of them must be answered in C."""
    stepper = ContactStepper(robot, ground, points)
    compiled = stepper.kept
    if compiled is None:
        pytest.skip("no C compiler: the contact step is Python's alone")
    answered: list[bool] = []

    def counted(*arguments):
        done = compiled(*arguments)
        answered.append(done is not None)
        return done

    v, guess, weight = np.zeros(robot.nv), None, 9.81 * robot.total_mass
    for step in range(settle + steps):
        tau = controller(q, v)
        stepper.kept = None
        theirs = stepper.step(q, v, tau, 1e-3, ContactSettings(), guess)
        if step >= settle:
            stepper.kept = counted
            ours = stepper.step(q, v, tau, 1e-3, ContactSettings(), guess)
            assert ours.iterations == theirs.iterations == 0
            assert np.abs(ours.forces - theirs.forces).max() < 1e-12 * weight  # [N]
            assert np.abs(ours.v - theirs.v).max() < 1e-14 and np.abs(ours.slip - theirs.slip).max() < 1e-14
            assert np.abs(ours.q - theirs.q).max() < 1e-16 and np.array_equal(ours.gaps, theirs.gaps)
            theirs = ours
        q, v, guess = theirs.q, theirs.v, theirs.impulses
    assert answered == [True] * steps


def test_the_compiled_step_of_kept_modes_is_the_python_polish_on_solo12(solo):
    """solo12 landing from 1 mm, then standing while its legs move (a floating base)."""
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), 1e-4) for foot in FEET)
    q = solo.neutral_configuration()
    q[2] -= contact_kinematics(solo, q, Ground(), points)[0].min() - 1e-3
    target = q[7:] + 0.02

    def hold(q, v):
        return np.r_[np.zeros(6), 5.0 * (target - q[7:]) - 0.1 * v[6:]]

    _c_against_numpy(solo, Ground(friction=0.8), points, q, hold, 40, 60)


def test_the_compiled_step_of_kept_modes_is_the_python_polish_on_a_fixed_arm():
    """ur5 falling onto a table 2 cm below its tool, then resting on it (a fixed base, one point)."""
    arm = robodyn.load("ur5")
    tip = (ContactPoint("tip", "tool0", (0.0, 0.0, 0.0)),)
    q = np.zeros(arm.nq)
    ground = Ground(height=contact_kinematics(arm, q, Ground(), tip)[0][0] - 0.02, friction=5.0)
    _c_against_numpy(arm, ground, tip, q, lambda q, v: -0.5 * v, 300, 50)


def _kept_arguments(robot, ground, points, q, guess):
    """The C step's arguments at ``q``, at rest, with ``guess`` (the stepper's own; the joints' torques their ``G``)."""
    stepper = ContactStepper(robot, ground, points)
    model, data = stepper.model, stepper.data
    pin.crba(model, data, q)
    pin.cholesky.decompose(model, data)
    inverse, bias = pin.cholesky.computeMinv(model, data), pin.nonLinearEffects(model, data, q, np.zeros(robot.nv))
    tau = np.r_[np.zeros(6), bias[6:]]  # the joints hold their own weight, the feet the base's
    settings = np.array([1e-3, 0.2, ground.friction, stepper.level])
    centres, zero = stepper.centres(q), np.zeros(robot.nv)
    arrays = [inverse, data.J, centres, stepper.offsets, stepper.mask, zero, tau, bias, guess, stepper.axes]
    return stepper.kept, [*arrays, settings, q]


def test_the_compiled_step_declines_what_is_not_its_case(solo, box):
    """Arrays of a wrong size, type or layout, a contact on its cone, more rows than nv:
    None (Python's path); the case itself: the impulses that hold solo12 up."""
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), 1e-4) for foot in FEET)
    q = solo.neutral_configuration()
    q[2] -= contact_kinematics(solo, q, Ground(), points)[0].min()
    weight = np.tile([0.0, 0.0, solo.total_mass * 9.81 * 1e-3 / 4], 4)  # [N s]
    kept, arguments = _kept_arguments(solo, Ground(friction=0.8), points, q, weight)
    if kept is None:
        pytest.skip("no C compiler: the contact step is Python's alone")
    done = kept(*arguments)  # the case itself
    assert done is not None and abs(done[2][:, 2].sum() / (solo.total_mass * 9.81) - 1) < 1e-2  # holding it up
    assert np.abs(done[4] - ContactStepper(solo, Ground(), points).locate(q)[1]).max() < 1e-15  # its gaps
    for index, bad in (
        (3, arguments[3][:3]),
        (1, arguments[1].astype(np.float32)),
        (1, np.ascontiguousarray(arguments[1])),
        (0, np.asfortranarray(arguments[0][:, :6])),
        (8, list(arguments[8])),
    ):
        assert kept(*arguments[:index], bad, *arguments[index + 1 :]) is None
    on_cone = weight.copy()
    on_cone[0] = 0.8 * on_cone[2]  # the first foot's impulse on its cone: it slipped
    assert kept(*arguments[:8], on_cone, *arguments[9:]) is None
    corners = contact_points(box, "collision").points
    q = box.neutral_configuration()
    q[2] = 0.05
    kept, arguments = _kept_arguments(box, Ground(friction=0.5), corners, q, np.tile([0.0, 0.0, 2.5 * 9.81 * 1e-3 / 4], 8))
    assert kept(*arguments) is None  # four resting corners: 12 rows of a 6-dof body


def test_without_a_c_compiler_the_step_is_numpys(solo, monkeypatch, tmp_path):
    """No compiler (and nothing built in the cache): no C step; a step is numpy's."""

    def missing() -> str:
        raise CompilerNotFoundError("cc")

    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    monkeypatch.setattr(build, "find_compiler", missing)
    compiled_contact.kept_step.cache_clear()
    try:
        stepper = ContactStepper(solo, Ground(friction=0.8), contact_points(solo, list(FEET)).points)
        assert stepper.kept is None
        q = solo.neutral_configuration()
        step = stepper.step(q, np.zeros(solo.nv), np.zeros(solo.nv), 1e-3, ContactSettings(), None)
        assert step.converged and np.isfinite(step.q).all()
    finally:
        compiled_contact.kept_step.cache_clear()  # built (or found) again for the tests after


def test_limit_rows_step_in_the_stepper_as_in_the_general_step_and_the_compiled_step_declines_them():
    """The stop pendulum (one dof: Pinocchio's ``data.J`` is then 1-D) dropped onto its stop
    under gravity 7.3: the stepper's run (its C step tried while no limit row is in reach)
    and the general step's agree, the stop carrying gravity's torque; no C call comes with a
    row in reach."""
    from robodyn.sim.contact_limits import LimitRows
    from tests.sim.test_contact_limits import FAR, GRAVITY, LEVER, MASS, PENDULUM, TIP, UPPER

    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    rows, points, settings, dt = LimitRows(robot), tuple(TIP), ContactSettings(), 1e-3
    stepper = ContactStepper(robot, FAR, points, rows)
    compiled, in_reach, calls = stepper.kept, [False], []

    def counted(*arguments):
        calls.append(in_reach[0])
        return compiled(*arguments)

    if compiled is not None:
        stepper.kept = counted
    runs = []
    for fast in (True, False):
        q, v, guess, held, run = np.array([0.1]), np.zeros(1), None, None, []
        for _ in range(300):
            free = v + dt * np.linalg.solve(robot.mass_matrix(q), -robot.nonlinear_effects(q, v))
            in_reach[0] = len(rows.near(q, v, free, dt)) > 0
            if fast:
                result = stepper.step(q, v, np.zeros(1), dt, settings, guess, held)
            else:
                result = generic_step(robot, q, v, np.zeros(1), dt, FAR, points, settings, guess, limits=rows, held=held)
            run.append((result.q, result.v, result.limits))
            q, v, guess, held = result.q, result.v, result.impulses, result.limits
        runs.append(run)
    for index in range(3):
        assert _largest_difference(runs, index) < 1e-12
    assert abs(runs[0][-1][0][0] - UPPER) < 1e-12  # on its stop
    weight = MASS * abs(GRAVITY[2]) * LEVER * np.cos(UPPER)  # gravity's torque about the hinge, [N m]
    assert abs(runs[0][-1][2][1] / (weight * dt) - 1) < 1e-9  # the upper stop's impulse carries it
    assert compiled is None or (calls and not any(calls))  # the C step tried, never with a row in reach


def test_a_singular_mass_matrix_is_refused_by_both_steps_in_one_sentence_naming_the_robot():
    """A link that moves no mass (the tip of tests/sim/test_limits.py's arm): the general
    step (``M`` solved) and the stepper (``M⁻¹`` not finite) refuse it alike."""
    from tests.sim.test_limits import MASSLESS_TIP

    robot, ground = robodyn.load(MASSLESS_TIP), Ground(height=-1.0)
    points, zeros = (ContactPoint("tip", "l1", (0.4, 0.0, 0.0)),), np.zeros(2)
    sentence = (
        "robot 'massless_tip': the mass matrix is singular, so forward dynamics is undefined (the accelerations are not finite)."
    )
    with pytest.raises(SingularMassMatrixError) as general:
        generic_step(robot, zeros, zeros, zeros, 1e-3, ground, points, ContactSettings(), None)
    with pytest.raises(SingularMassMatrixError) as fast:
        ContactStepper(robot, ground, points).step(zeros, zeros, zeros, 1e-3, ContactSettings(), None)
    assert str(general.value) == str(fast.value) == sentence and general.value.joints == fast.value.joints == []


def test_a_mimic_arm_with_no_contact_point_steps_freely_by_its_forward_dynamics():
    """No contact point (the general step: a mimic robot): no row at all, and the step is
    semi-implicit Euler of the forward dynamics, ``v⁺ = v + dt a(q, v, τ)``."""
    arm = robodyn.load(DATA.parent / "mimic_arm.urdf", gravity=(0.4, -0.3, -7.5))
    q, v, tau = np.full(arm.nq, 0.2), np.linspace(-0.5, 0.5, arm.nv), np.linspace(0.3, -0.1, arm.nv)
    gaps, jacobian = contact_kinematics(arm, q, Ground(), ())
    assert gaps.shape == (0,) and jacobian.shape == (0, arm.nv)
    step = contact_step(arm, q, v, tau, 1e-3, Ground(), ())
    assert step.forces.shape == (0, 3)
    assert np.abs(step.v - (v + 1e-3 * arm.forward_dynamics(q, v, tau))).max() < 1e-12


def test_without_the_polish_standing_is_admms_even_where_the_compiled_step_could_take_it(solo):
    """``polish=False`` asks for ADMM's answer: solo12 standing, from last step's impulses
    off by 10 %, the stepper runs ADMM (iterations > 0), neither the compiled step of kept
    modes nor numpy's polish; with the polish, the kept modes answer at once (0 iterations,
    the negative control)."""
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), 1e-4) for foot in FEET)
    ground, q = Ground(friction=0.8), solo.neutral_configuration()
    q[2] -= contact_kinematics(solo, q, ground, points)[0].min()  # the feet on the ground
    v, tau = np.zeros(solo.nv), np.zeros(solo.nv)
    stepper, guess = ContactStepper(solo, ground, points), None
    for _ in range(20):  # landed, standing
        step = stepper.step(q, v, tau, 1e-3, ContactSettings(), guess)
        q, v, guess = step.q, step.v, step.impulses
    assert stepper.step(q, v, tau, 1e-3, ContactSettings(polish=False), 1.1 * guess).iterations > 0
    assert stepper.step(q, v, tau, 1e-3, ContactSettings(), 1.1 * guess).iterations == 0


def test_a_torque_too_large_to_integrate_is_a_diverged_run_not_a_singular_mass_matrix(box):
    """1e200 N on the box: the free velocity overflows, the mass matrix is fine — the run
    says it diverged (a smaller step), never that ``M`` is singular."""
    from robodyn.exceptions import SimulationError
    from robodyn.sim.contact_run import simulate_contact

    q = box.neutral_configuration()
    q[2] = 0.05
    with np.errstate(all="ignore"), pytest.raises(SimulationError, match="diverged at t = 0 s"):
        simulate_contact(box, ground=Ground(friction=0.5), duration=0.01, q0=q, controller=lambda t, q, v: np.full(6, 1e200))
