"""The thin single calls (ModelHandle.single_call): Pinocchio's numbers, every bad entry refused, thread-safe.

The fast path checks only the result (and, for M, the world-attached joints' q): a NaN or
inf anywhere in q, v, a or tau must still come back as an InputError naming it. The robots
here are loaded with ``engine="pinocchio"`` (their compiled kernels, if built, would answer
otherwise: tests/compiled/test_engine.py).
"""

from __future__ import annotations

import threading

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import InputError, NonFiniteResultError
from tests.conftest import FAST_ZOO, NONDEGENERATE_CASES

FIXED = [*FAST_ZOO, "panda_mimic", "gripper", "rp_arm", "oblique", "oblique_locked"]


def _load(name):
    if name in NONDEGENERATE_CASES:
        path, options = NONDEGENERATE_CASES[name]
        return robodyn.load(str(path), **options, engine="pinocchio")
    if name == "panda_mimic":  # as loaded: a mimic finger
        return robodyn.load("panda", engine="pinocchio")
    return robodyn.load(name, engine="pinocchio", **({"lock": {"panda_finger_joint1": 0.0}} if name == "panda" else {}))


def _calls(robot, q, v, a):
    return {
        "inverse_dynamics": lambda q=q, v=v, a=a: robot.inverse_dynamics(q, v, a),
        "forward_dynamics": lambda q=q, v=v, a=a: robot.forward_dynamics(q, v, a),
        "mass_matrix": lambda q=q, v=v, a=a: robot.mass_matrix(q),
        "gravity": lambda q=q, v=v, a=a: robot.gravity(q),
        "nonlinear_effects": lambda q=q, v=v, a=a: robot.nonlinear_effects(q, v),
    }


@pytest.mark.parametrize("name", FIXED)
def test_a_nan_or_inf_in_any_entry_is_refused_by_every_single_call(name, rng):
    robot = _load(name)
    q, v, a = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    for method, call in _calls(robot, q, v, a).items():
        assert np.isfinite(call()).all(), method
    for argument, size in (("q", robot.nq), ("v", robot.nv), ("a", robot.nv)):
        for index in range(size):
            for bad in (np.nan, np.inf):
                values = {"q": q.copy(), "v": v.copy(), "a": a.copy()}
                values[argument][index] = bad
                for method, call in _calls(robot, values["q"], values["v"], values["a"]).items():
                    uses = {"mass_matrix": "q", "gravity": "q", "nonlinear_effects": "qv"}.get(method, "qva")
                    if argument in uses:
                        with pytest.raises(InputError):
                            call()


def test_crba_ignores_the_root_joints_q_so_the_mass_matrix_checks_it():
    """Negative control: raw CRBA returns a finite M for a NaN root q (what checking the
    result alone would let through); the single call refuses it."""
    robot = robodyn.load("ur5", engine="pinocchio")
    q = robot.neutral_configuration()
    q[0] = np.nan
    assert np.isfinite(pin.crba(robot.model, robot.model.createData(), q)).all()
    with pytest.raises(InputError, match="q"):
        robot.mass_matrix(q)


@pytest.mark.parametrize("name", ["ur5", "oblique"])
def test_single_calls_are_pinocchios_numbers(name, rng):
    robot = _load(name)
    model, data = robot.model, robot.model.createData()
    q, v, a = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    mass = pin.crba(model, data, q)
    mass = np.triu(mass) + np.triu(mass, 1).T
    assert np.array_equal(robot.inverse_dynamics(q, v, a), pin.rnea(model, data, q, v, a))
    assert np.array_equal(robot.forward_dynamics(q, v, a), pin.aba(model, data, q, v, a))
    assert np.array_equal(robot.mass_matrix(q), mass)
    assert np.array_equal(robot.gravity(q), pin.computeGeneralizedGravity(model, data, q))
    assert np.array_equal(robot.nonlinear_effects(q, v), pin.nonLinearEffects(model, data, q, v))


def test_one_robot_used_from_several_threads_gives_each_its_own_results(rng):
    robot = robodyn.load("ur5", engine="pinocchio")
    states = [(robot.random_configuration(rng), rng.normal(size=6), rng.normal(size=6)) for _ in range(7)]
    expected = [(robot.inverse_dynamics(*s), robot.mass_matrix(s[0]), robot.forward_dynamics(*s)) for s in states]
    failures = []

    def work(index: int) -> None:
        q, v, a = states[index]
        for _ in range(300):
            got = (robot.inverse_dynamics(q, v, a), robot.mass_matrix(q), robot.forward_dynamics(q, v, a))
            if not all(np.array_equal(x, y) for x, y in zip(got, expected[index], strict=True)):
                failures.append(index)
                return

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(states))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []


def test_pinocchios_python_crba_returns_both_triangles_which_the_mass_matrix_relies_on(rng):
    """The single call returns Python ``pin.crba``'s M as it comes (no mirroring): that is
    only right while the binding fills the lower triangle, checked here against the
    reference's M (independent of Pinocchio)."""
    from robodyn.reference import load as load_reference

    robot = robodyn.load("ur5", engine="pinocchio")
    q = robot.random_configuration(rng)
    mass = pin.crba(robot.model, robot.model.createData(), q)
    assert np.array_equal(mass, mass.T) and np.abs(np.tril(mass, -1)).max() > 0.01
    assert np.array_equal(robot.mass_matrix(q), mass)
    reference = load_reference("ur5")
    np.testing.assert_allclose(robot.mass_matrix(q), reference.mass_matrix(q), atol=1e-9)


def test_only_revolute_robots_with_sane_constants_skip_the_check_of_their_results():
    from robodyn.dynamics.handle import bounded_for_finite_q

    assert bounded_for_finite_q(robodyn.load("ur5").model)
    assert bounded_for_finite_q(robodyn.load("panda", lock={"panda_finger_joint1": 0.0}).model)
    assert not bounded_for_finite_q(robodyn.load("rp_arm").model)  # a prismatic joint
    # negative control: a revolute robot whose constants could overflow
    model = robodyn.load("ur5").model.copy()
    model.inertias[3].mass = 1e60
    assert not bounded_for_finite_q(model)


@pytest.mark.parametrize("name", ["ur5", "rp_arm", "oblique", "double_pendulum_continuous"])
def test_huge_finite_values_give_pinocchios_finite_numbers_or_a_refusal_never_inf(name, rng):
    """±1e308 in any entry: a finite result equals raw Pinocchio's, an overflow is refused
    (NonFiniteResultError), and the raw call shows it would have returned inf or NaN."""
    robot = _load(name)
    model, data = robot.model, robot.model.createData()
    q, v, a = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    raws = {
        "inverse_dynamics": lambda q, v, a: pin.rnea(model, data, q, v, a),
        "mass_matrix": lambda q, v, a: pin.crba(model, data, q),
        "gravity": lambda q, v, a: pin.computeGeneralizedGravity(model, data, q),
        "nonlinear_effects": lambda q, v, a: pin.nonLinearEffects(model, data, q, v),
    }
    overflows = 0
    for argument, size in (("q", robot.nq), ("v", robot.nv), ("a", robot.nv)):
        for index in range(size):
            for huge in (1e308, -1e308, 1e200):
                values = {"q": q.copy(), "v": v.copy(), "a": a.copy()}
                values[argument][index] = huge
                for method, call in _calls(robot, values["q"], values["v"], values["a"]).items():
                    if method == "forward_dynamics":
                        continue
                    with np.errstate(all="ignore"):
                        expected = raws[method](values["q"], values["v"], values["a"])
                    if np.isfinite(expected).all():
                        assert np.array_equal(call(), expected), (method, argument, index)
                    else:
                        overflows += 1
                        with pytest.raises((NonFiniteResultError, InputError)):
                            call()
    assert overflows > 0  # the raw calls did overflow somewhere: the refusals were exercised


@pytest.mark.parametrize("name", ["ur5", "rp_arm"])
def test_a_column_or_a_batch_of_one_keeps_the_shape_rule(name, rng):
    """Pinocchio takes an (nq, 1) column as one state; robodyn refuses it (nq states of one
    entry), and a (1, nq) batch of one gives a (1, ·) stack."""
    robot = _load(name)
    q = robot.random_configuration(rng)
    for call in (robot.mass_matrix, robot.gravity):
        with pytest.raises(InputError):
            call(q[:, None])
        assert call(q[None, :]).shape[0] == 1
        np.testing.assert_array_equal(call(q[None, :])[0], call(q))


def test_threads_hammering_different_states_get_their_own_gravity_and_mass_matrix(rng):
    robot = robodyn.load("panda", lock={"panda_finger_joint1": 0.0}, engine="pinocchio")
    states = [(robot.random_configuration(rng), rng.normal(size=robot.nv)) for _ in range(5)]
    expected = [(robot.gravity(q), robot.mass_matrix(q), robot.nonlinear_effects(q, v)) for q, v in states]
    failures = []

    def work(index: int) -> None:
        q, v = states[index]
        for _ in range(500):
            got = (robot.gravity(q), robot.mass_matrix(q), robot.nonlinear_effects(q, v))
            if not all(np.array_equal(x, y) for x, y in zip(got, expected[index], strict=True)):
                failures.append(index)
                return

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(states))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    # negative control: the states' results differ, so a shared Data would show
    assert not np.array_equal(expected[0][0], expected[1][0])
