"""The step against the fastest mode: a run that will diverge is warned about at its start,
with the step that would not; a divergence inside a step is reported as a divergence."""

from __future__ import annotations

import contextlib
import shutil
import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import RobodynWarning, SimulationError
from robodyn.sim.control import PDGravity
from robodyn.sim.plan import plan
from robodyn.sim.stability import clearly_stable, largest_stable_step, step_warning

LIGHT_DAMPED = """<robot name="light_damped">
  <link name="base"/>
  <joint name="arm" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="30"/></joint>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="finger" type="revolute"><parent link="arm"/><child link="finger"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="30"/><dynamics damping="0.01"/></joint>
  <link name="finger"><inertial><origin xyz="0 0 0"/><mass value="1e-3"/>
    <inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial></link>
</robot>"""


def _run(robot, dt, steps, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            trajectory = robodyn.simulate(
                robot, options.pop("q0"), np.zeros(robot.nv), steps * dt, dt, limits="ignore", engine="pinocchio", **options
            )
        except SimulationError as error:
            trajectory = error
    return trajectory, [str(w.message) for w in caught if issubclass(w.category, RobodynWarning)]


def test_stiff_gains_are_warned_about_and_the_suggested_step_holds():
    """rp_arm under PD with kp = 1e7: the fastest mode needs dt under ~7e-4 s. At 1 ms the run
    is warned about and diverges (a SimulationError, not an input error); at half the
    suggested step it stays finite and nothing is said."""
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    law = PDGravity(robot, q0 + 0.1, kp=1e7, kd=20.0)
    limit, joint, cause = largest_stable_step(plan(robot, q0, np.zeros(2), 0.1, 1e-3, controller=law))
    assert 1e-4 < limit < 1e-3 and cause == "the PDGravity gains" and joint == "joint1"
    diverged, said = _run(robot, 1e-3, 100, q0=q0, controller=law)
    assert isinstance(diverged, SimulationError) and type(diverged) is SimulationError
    assert len(said) == 1 and f"use dt <= {limit:.2g} s" in said[0] and "PDGravity gains" in said[0]
    calm, said = _run(robot, limit / 2, 200, q0=q0, controller=law)
    assert not isinstance(calm, SimulationError) and np.isfinite(calm.q).all() and said == []


def test_damping_on_a_light_link_is_warned_about_and_named():
    """A finger of 1e-7 kg m² with damping 0.01 N m s/rad: the rate b / m = 1e5 1/s needs
    dt under ~3e-5 s; the same robot without its damping is not warned about."""
    robot = robodyn.load(LIGHT_DAMPED)
    q0 = np.array([0.3, 0.2])
    diverged, said = _run(robot, 1e-3, 50, q0=q0)
    assert isinstance(diverged, SimulationError)
    assert len(said) == 1 and "'finger'" in said[0] and "damping" in said[0]
    calm, said = _run(robot, 2e-5, 100, q0=q0)
    assert np.isfinite(calm.q).all() and said == []
    _, said = _run(robot, 1e-3, 50, q0=q0, joint_friction=False)
    assert said == []


def test_a_users_controller_is_not_called_by_the_check():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    calls = []

    def law(t, q, v):
        calls.append(t)
        return -v

    assert step_warning(plan(robot, q0, np.zeros(2), 0.01, 1e-3, controller=law)) is None
    assert calls == []
    robodyn.simulate(robot, q0, np.zeros(2), 0.01, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    assert len(calls) == 4 * 10  # the four RK4 stages of each step, nothing more


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_the_limit_follows_the_integrators_stability_region(integrator):
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    law = PDGravity(robot, q0, kp=1e6, kd=20.0)
    limit, _, _ = largest_stable_step(plan(robot, q0, np.zeros(2), 0.1, 1e-3, controller=law, integrator=integrator))
    rk4, _, _ = largest_stable_step(plan(robot, q0, np.zeros(2), 0.1, 1e-3, controller=law))
    assert limit == pytest.approx(rk4 * (2.0 / 2.78 if integrator != "rk4" else 1.0))


def test_an_operational_space_task_starting_at_a_singularity_is_warned_about():
    """ur5 stretched (elbow straight): the warning says the task inertia is damped there (the
    default variable damping keeps the torques under 100 N m); with it off the run stops
    within 10 ms and the warning says the torques are unbounded. A bent start, and the planar
    RP arm's direction it never moves in, are not warned about."""
    from robodyn.sim.operational_space import OperationalSpace
    from robodyn.sim.stability import task_warning

    robot = robodyn.load("ur5")
    stretched = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
    law = OperationalSpace(robot, None, [0.3, 0.2, 0.4], orientation=[0.0, 0.0, 0.0])
    said = task_warning(plan(robot, stretched, np.zeros(6), 0.01, 1e-3, controller=law))
    assert said is not None and "singularity" in said and "damped there" in said
    calm, _ = _run(robot, 1e-3, 200, q0=stretched, controller=law)
    assert np.abs(calm.tau).max() < 100.0
    undamped = OperationalSpace(robot, None, [0.3, 0.2, 0.4], orientation=[0.0, 0.0, 0.0], singular_damping=0.0)
    said = task_warning(plan(robot, stretched, np.zeros(6), 0.01, 1e-3, controller=undamped))
    assert said is not None and "without bound" in said
    stopped, _ = _run(robot, 1e-3, 200, q0=stretched, controller=undamped)
    assert isinstance(stopped, SimulationError)
    assert task_warning(plan(robot, stretched + 0.4, np.zeros(6), 0.01, 1e-3, controller=law)) is None
    rp_arm = robodyn.load("rp_arm")
    planar = OperationalSpace(rp_arm, None, [0.7, 0.0, 0.7])
    assert task_warning(plan(rp_arm, np.array([0.3, 0.1]), np.zeros(2), 0.01, 1e-3, controller=planar)) is None


def test_a_checked_call_failing_on_a_blown_up_state_is_a_divergence_not_a_singular_mass_matrix():
    """A law whose checked dynamics call fails on a state that blew up (here: it raises what
    such a call raises) while M was regular: the run reports a divergence, naming the time and
    the fastest joint, never a singular mass matrix."""
    from robodyn.exceptions import SingularMassMatrixError

    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()

    def law(t, q, v):
        if np.abs(v).max() > 50.0:
            raise SingularMassMatrixError(robot.name, [])
        return 1e7 * (q0 + 0.1 - q) - 20.0 * v

    with pytest.raises(SimulationError) as raised, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    assert type(raised.value) is SimulationError and "diverged" in str(raised.value)
    assert not isinstance(raised.value, SingularMassMatrixError)


def _fastest(plan_):
    """The fastest rate of the plant at the plan's start by the eigenvalues of ``linearize``'s A
    (the independent side of the screen's bound)."""
    from robodyn.sim.linearize import linearize

    damped = plan_.friction and not plan_.coulomb
    A, _ = linearize(plan_.robot, plan_.q0, plan_.v0, np.zeros(plan_.robot.nv), joint_friction=damped)
    return float(np.abs(np.linalg.eigvals(A)).max())


@pytest.mark.parametrize("name", ["light_damped", "panda", "oblique_floating", "gripper"])
def test_the_screens_bound_is_never_below_the_fastest_rate(name, rng):
    """The screen's bound (no eigenvalues) against the eigenvalues of the linearisation, at
    random states of a damped light finger, the panda (damped, mimic finger), a floating base
    moving (its −ad(v) block) and a mimic gripper; the bound without its velocity rows
    (negative control) falls below the damped finger's rate."""
    from robodyn.sim.stability import spectral_bound
    from tests.conftest import NONDEGENERATE_CASES

    if name == "light_damped":
        robot = robodyn.load(LIGHT_DAMPED)
    elif name in NONDEGENERATE_CASES:
        path, options = NONDEGENERATE_CASES[name]
        robot = robodyn.load(path, gravity=[0.8, 1.1, -9.3], **options)
    else:
        robot = robodyn.load(name)
    for q, v in zip(robot.random_configuration(rng, 3), 2.0 * rng.normal(size=(3, robot.nv)), strict=True):
        run = plan(robot, q, v, 0.01, 1e-3, limits="ignore")
        fastest = _fastest(run)
        damping = robot.joint_damping if run.friction else np.zeros(robot.nv)
        by_q, by_v, inverse = robot.forward_dynamics_derivatives(q, v, -damping * v)
        by_v = by_v - inverse * damping
        top = float(np.abs(pin.Motion(v[:6]).action).sum(axis=1).max()) if robot.floating_base else 0.0
        rows_q, rows_v = np.abs(by_q).sum(axis=1), np.abs(by_v).sum(axis=1)
        assert spectral_bound(top, rows_q, rows_v) >= fastest * (1 - 1e-12)
        if name == "light_damped":
            assert spectral_bound(top, rows_q, np.zeros(robot.nv)) < 0.5 * fastest


def test_a_passive_run_that_fits_its_step_is_cleared_without_a_linearisation(monkeypatch):
    """The screen clears the panda arm at 1 ms with one derivative call (the eigenvalues and
    linearize are not reached: simulate's fixed cost); at a step that does not fit, the full
    check runs and warns as before, with the same sentence."""
    from robodyn.sim import stability

    robot = robodyn.load("panda", lock={"panda_finger_joint1": 0.0})
    q0 = 0.5 * np.add(*robot.physical_limits())
    calls = []
    original = stability.linearize
    monkeypatch.setattr(stability, "linearize", lambda *a, **k: calls.append(1) or original(*a, **k))
    fits = plan(robot, q0, np.full(7, 0.1), 0.01, 1e-3, limits="ignore")
    assert stability.clearly_stable(fits) and step_warning(fits) is None and calls == []
    limit, _, _ = largest_stable_step(fits)
    assert calls and limit > 1e-3  # the full check agrees (negative control: it linearizes)
    calls.clear()
    too_long = plan(robot, q0, np.full(7, 0.1), 2 * limit, 2 * limit, limits="ignore")
    assert not stability.clearly_stable(too_long)
    said = step_warning(too_long)
    assert calls and said is not None and f"use dt <= {limit:.2g} s" in said


def test_the_screen_never_clears_a_step_the_eigenvalues_refuse():
    """PD + gravity on the panda arm from soft to stiff gains, steps from 10 µs to 10 ms, both
    integrators: whenever the screen clears a step, the eigenvalues' largest stable step holds
    it; the screen clears some steps and not others (it decides something)."""
    robot = robodyn.load("panda", lock={"panda_finger_joint1": 0.0})
    q0 = 0.5 * np.add(*robot.physical_limits())
    cleared = []
    for kp, kd in ((50.0, 2.0), (1e4, 50.0), (1e6, 500.0)):
        law = PDGravity(robot, q0 + 0.1, kp=kp, kd=kd)
        for integrator in ("rk4", "semi-implicit-euler"):
            limit, _, _ = largest_stable_step(plan(robot, q0, np.full(7, 0.2), 0.0, 1e-3, controller=law, integrator=integrator))
            for dt in np.geomspace(1e-5, 1e-2, 7):
                start = plan(robot, q0, np.full(7, 0.2), 0.0, dt, controller=law, integrator=integrator)
                if clearly_stable(start):
                    assert dt <= limit, (kp, integrator, dt, limit)
                cleared.append(clearly_stable(start))
    assert any(cleared) and not all(cleared)


@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
def test_a_controller_in_c_is_screened_by_its_twin_and_warned_about_by_itself(monkeypatch):
    """rp_arm under PD in C: a soft law is cleared with the twin's feedback (the Python law is
    not called by the check); a stiff one is warned about with the very sentence the
    Pinocchio engine gives (the check then runs on the law itself)."""
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    calls = []
    original = PDGravity.__call__
    monkeypatch.setattr(PDGravity, "__call__", lambda self, t, q, v: calls.append(t) or original(self, t, q, v))
    soft = PDGravity(robot, q0 + 0.1, kp=100.0, kd=5.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.simulate(robot, q0, np.zeros(2), 0.01, 1e-3, controller=soft, engine="compiled", limits="ignore")
    assert calls == [] and not [w for w in caught if issubclass(w.category, RobodynWarning)]
    stiff = PDGravity(robot, q0 + 0.1, kp=1e7, kd=20.0)
    said = {}
    for engine in ("compiled", "pinocchio"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with contextlib.suppress(SimulationError):  # it diverges, as warned
                robodyn.simulate(robot, q0, np.zeros(2), 0.01, 1e-3, controller=stiff, engine=engine, limits="ignore")
        said[engine] = [str(w.message) for w in caught if issubclass(w.category, RobodynWarning)]
    assert len(said["compiled"]) == 1 and said["compiled"] == said["pinocchio"] and "PDGravity gains" in said["compiled"][0]


def test_the_suggested_step_is_the_largest_of_the_one_two_five_series_within_the_limit():
    from robodyn.sim.stability import round_step

    assert round_step(1.2e-5) == pytest.approx(1e-5)
    assert round_step(7.2e-4) == pytest.approx(5e-4)
    assert round_step(2.0e-3) == pytest.approx(2e-3)
    assert round_step(1.99e-3) == pytest.approx(1e-3)
    for limit in np.geomspace(1e-7, 1.0, 41):
        step = round_step(limit)
        assert step <= limit * (1 + 1e-12) and step > limit / 2.5 - 1e-18
        assert round(1.0 / step) * step == pytest.approx(1.0)  # a whole number of steps in 1 s
