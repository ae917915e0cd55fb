"""Excitation and identification: limits, noise-free recovery, 3σ with noise, physical
consistency, URDF write-back, and the CLI."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.dynamics.regressor import inertial_parameters
from robodyn.exceptions import IdentificationError
from robodyn.ident import base_parameters, excite, identified_urdf, identify
from robodyn.ident.base import joint_ranges, random_states
from robodyn.trajectory import Trajectory
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def rp_arm():
    robot = robodyn.load("rp_arm")
    base = base_parameters(robot)
    excitation = excite(robot, duration=4.0, harmonics=3, iterations=15, base=base)
    return robot, base, excitation


def data_of(robot, excitation, rate=50.0):
    t, q, v, a, tau = excitation.sample(robot, rate=rate)
    return Trajectory(t, q, v, a, tau, list(robot.joint_names), robot.name)


def test_excitation_within_limits_periodic_and_better_conditioned(rp_arm):
    robot, _base, excitation = rp_arm
    assert excitation.condition < excitation.initial_condition and excitation.condition < 100
    t = np.linspace(0, excitation.period, 4001)
    q, v, a = excitation.evaluate(t)
    lower, upper = joint_ranges(robot)
    assert np.all(q >= lower) and np.all(q <= upper)
    assert np.all(np.abs(v) <= excitation.velocity_limit) and np.all(np.abs(a) <= excitation.acceleration_limit)
    np.testing.assert_allclose(q[0], q[-1], atol=1e-12)  # periodic
    np.testing.assert_allclose(v[0], v[-1], atol=1e-12)
    # v and a are the derivatives of q (the series' formulas), by central differences
    dt = t[1] - t[0]
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * dt), v[1:-1], atol=1e-4 * np.abs(v).max())
    np.testing.assert_allclose((v[2:] - v[:-2]) / (2 * dt), a[1:-1], atol=1e-4 * np.abs(a).max())


@pytest.mark.parametrize("method", ["ls", "wls"])
def test_noise_free_recovery(rp_arm, method):
    robot, base, excitation = rp_arm
    result = identify(robot, data_of(robot, excitation), method=method, base=base)
    np.testing.assert_allclose(result.values, base.values, rtol=0, atol=1e-8 * np.abs(base.values).max())
    assert result.relative_error < 1e-12


def test_noise_free_recovery_ur5():
    robot = robodyn.load("ur5")
    base = base_parameters(robot)
    q, v, a = random_states(robot, 120, np.random.default_rng(8))  # random states excite everything too
    data = Trajectory(np.arange(120.0), q, v, a, robot.inverse_dynamics(q, v, a), list(robot.joint_names), robot.name)
    result = identify(robot, data, base=base)
    assert np.abs(result.values - base.values).max() <= 1e-8 * np.abs(base.values).max()


@pytest.mark.parametrize("method", ["ls", "wls"])
def test_with_noise_true_values_within_three_sigma(rp_arm, method):
    robot, base, excitation = rp_arm
    data = data_of(robot, excitation, rate=100.0)
    rng = np.random.default_rng(3)
    sigma = np.array([0.5, 0.05])  # [N m], [N]: different per joint (what WLS is for)
    noisy = data.tau + rng.normal(size=data.tau.shape) * sigma
    result = identify(robot, data, noisy, method=method, base=base)
    z = (result.values - base.values) / result.std
    assert np.all(np.abs(z) < 3), z
    # Negative control: a value shifted by 10 σ is outside.
    assert np.abs((result.values + 10 * result.std - base.values) / result.std).max() > 3
    if method == "wls":  # per-joint noise levels estimated
        np.testing.assert_allclose(
            np.sqrt(np.mean((noisy - result.predict(data.q, data.v, data.a)) ** 2, axis=0)), sigma, rtol=0.1
        )


def test_physical_is_consistent_and_writes_a_urdf(rp_arm, tmp_path):
    robot, base, excitation = rp_arm
    data = data_of(robot, excitation, rate=100.0)
    noisy = data.tau + np.random.default_rng(4).normal(size=data.tau.shape) * 0.05
    result = identify(robot, data, noisy, method="physical", base=base)
    ls = identify(robot, data, noisy, method="wls", base=base)
    assert result.solver in ("CLARABEL", "SCS")
    assert result.relative_error <= ls.relative_error * 1.01  # consistency costs (almost) nothing here
    for body in range(2):
        m, h, (xx, xy, yy, xz, yz, zz) = (
            result.standard[10 * body],
            result.standard[10 * body + 1 : 10 * body + 4],
            result.standard[10 * body + 4 : 10 * body + 10],
        )
        inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        pseudo = np.block([[0.5 * np.trace(inertia) * np.eye(3) - inertia, h[:, None]], [h[None], np.array([[m]])]])
        assert np.linalg.eigvalsh(pseudo).min() >= -1e-7 * max(1.0, m)
    text = identified_urdf(robot, result.standard, base.columns)
    identified = robodyn.load(text)
    np.testing.assert_allclose(inertial_parameters(identified), result.standard, atol=1e-9)
    # noise-free: the physical estimate recovers the base values closely too
    exact = identify(robot, data, method="physical", base=base)
    np.testing.assert_allclose(exact.values, base.values, atol=1e-5 * np.abs(base.values).max())


def test_refusals(rp_arm):
    robot, base, excitation = rp_arm
    data = data_of(robot, excitation)
    still = Trajectory(data.t, np.zeros_like(data.q) + 0.3, 0 * data.v, 0 * data.a, data.tau, data.joint_names, robot.name)
    with pytest.raises(IdentificationError, match="excite"):
        identify(robot, still, base=base)
    other = Trajectory(data.t, data.q, data.v, data.a, data.tau, ["a", "b"], robot.name)
    with pytest.raises(IdentificationError, match="joints"):
        identify(robot, other, base=base)
    with pytest.raises(robodyn.InputError, match="method"):
        identify(robot, data, method="magic", base=base)
    with pytest.raises(robodyn.InputError):
        identify(robot, data, data.tau[:, :1], base=base)
    with pytest.raises(robodyn.InputError):
        excite(robot, duration=-1.0)


def test_cli_excite_then_identify(tmp_path, capsys):
    trajectory, params, urdf = tmp_path / "traj.csv", tmp_path / "params.json", tmp_path / "identified.urdf"
    assert (
        main(
            [
                "excite",
                "rp_arm",
                "--duration",
                "3",
                "--harmonics",
                "2",
                "--iterations",
                "5",
                "--rate",
                "40",
                "--out",
                str(trajectory),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "condition number" in out and trajectory.exists()
    assert Trajectory.load(trajectory).tau.shape == (120, 2)
    assert (
        main(["identify", "rp_arm", str(trajectory), "--method", "physical", "--out", str(params), "--urdf-out", str(urdf)]) == 0
    )
    summary = json.loads(params.read_text())
    assert summary["method"] == "physical" and len(summary["base_parameters"]) == 6 and summary["relative_error"] < 1e-6
    robodyn.load(str(urdf))
    assert main(["identify", "rp_arm", "--base-parameters"]) == 0
    assert "Iyy[link1] + Iyy[link2]" in capsys.readouterr().out
    assert main(["identify", "rp_arm", str(trajectory), "--urdf-out", str(urdf)]) == 2
    assert "--urdf-out" in capsys.readouterr().err
    assert main(["identify", "rp_arm"]) == 2
    capsys.readouterr()
    assert main(["identify", "ur5", str(trajectory)]) == 2  # data of another robot
    error = capsys.readouterr().err
    assert "ur5" in error and "q[shoulder_pan_joint]" in error and error.count("\n") == 1


@pytest.mark.slow
def test_worked_example():
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "example_identification.py"), "--quick", "--json"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["excitation_condition"] < report["excitation_condition_start"]
    for method in ("ls", "physical"):
        found = report["methods"][method]
        assert abs(found["payload_mass_error"]) < 0.05  # of 2.5 kg
        assert found["payload_com_error"] < 0.005  # [m]
        assert found["validation_error"] < 0.1 * report["nominal_validation_error"]


def test_friction_is_identified(rp_arm):
    robot, _base, _excitation = rp_arm
    with_friction = base_parameters(robot, friction=True)
    # (the plain excitation may keep the slider still: its friction would be unidentifiable, and refused)
    excitation = excite(robot, duration=4.0, harmonics=3, iterations=15, base=with_friction)
    data = data_of(robot, excitation, rate=100.0)
    viscous, coulomb = np.array([0.3, 2.0]), np.array([0.8, 1.5])
    tau = data.tau + viscous * data.v + coulomb * np.sign(data.v)
    for method in ("ls", "physical"):
        result = identify(robot, data, tau, method=method, base=with_friction)
        found = dict(zip(result.base.names, result.values, strict=True))
        np.testing.assert_allclose([found["fv[joint1]"], found["fv[joint2]"]], viscous, rtol=1e-4)
        np.testing.assert_allclose([found["fc[joint1]"], found["fc[joint2]"]], coulomb, rtol=1e-4)
    # Negative control: without friction columns the same data are not explained.
    assert identify(robot, data, tau).relative_error > 1e-3


def test_written_urdf_merges_welded_links_and_the_reference_agrees(rng):
    import robodyn.reference as reference
    from robodyn.reference.regressor import reference_body_links, reference_parameters
    from tests.dynamics.test_regressor import MIMIC_URDF

    robot = robodyn.load(MIMIC_URDF)  # l3 carries the welded l4 (0.3 kg)
    q, v, a = random_states(robot, 150, rng)
    heavier = robodyn.attach_payload(robot, "l4", 0.4, com=(0.01, 0.02, -0.03))
    data = Trajectory(np.arange(150.0), q, v, a, heavier.inverse_dynamics(q, v, a), list(robot.joint_names), robot.name)
    result = identify(robot, data, method="physical")
    assert result.relative_error < 1e-4
    text = identified_urdf(robot, result.standard, result.base.columns)
    assert text.count("<inertial>") == 3  # l1, l2, l3 (l4's moved into l3)
    written = robodyn.load(text)
    np.testing.assert_allclose(inertial_parameters(written), result.standard, atol=1e-9)
    ref = reference.load(text)  # the independent reader merges the bodies the same way
    links = reference_body_links(ref)
    order = np.concatenate([10 * [lk for lk in ["l1", "l2", "l3"]].index(link) + np.arange(10) for link in links])
    np.testing.assert_allclose(reference_parameters(ref), result.standard[order], atol=1e-9)
    np.testing.assert_allclose(written.inverse_dynamics(q, v, a), data.tau, rtol=0, atol=1e-3 * np.abs(data.tau).max())


def _with_dynamics(urdf: str, values: dict[str, str]) -> str:
    import re

    for joint, attributes in values.items():
        urdf, count = re.subn(rf'(<joint name="{joint}"[^>]*>)', rf"\1<dynamics {attributes}/>", urdf)
        assert count == 1
    return urdf


def test_identifying_a_simulated_robot_with_joint_dynamics_recovers_its_damping_and_friction(rp_arm, tmp_path):
    """The rp_arm with ``<dynamics>`` and armature, simulated (stick–slip friction, armature
    in M) under computed torque along its exciting trajectory: the friction columns give back
    the file's b and f, the inertial base values the file's, and the identified URDF carries
    them in its ``<dynamics>``. Samples with a joint at rest (friction anywhere in ±f) are left out."""
    from robodyn.sim.control import ComputedTorque

    robot = rp_arm[0]
    excitation = excite(robot, duration=4.0, harmonics=3, iterations=15, base=base_parameters(robot, friction=True))
    text = _with_dynamics(
        robodyn.load("rp_arm").urdf, {"joint1": 'damping="0.3" friction="0.8"', "joint2": 'damping="2" friction="1.5"'}
    )
    plant = robodyn.load(text, armature={"joint2": 0.3})  # (on joint1 it would be one with link1's Izz)
    np.testing.assert_array_equal(inertial_parameters(plant, friction=True)[-4:], [0.3, 2.0, 0.8, 1.5])
    reference = lambda t: tuple(x[0] for x in excitation.evaluate(np.array([t])))  # noqa: E731
    q0, v0, _ = reference(0.0)
    trajectory = robodyn.simulate(plant, q0, v0, 4.0, 2e-3, controller=ComputedTorque(robot, reference))
    moving = np.all(trajectory.v != 0, axis=1)
    assert moving.mean() > 0.5  # it sticks at some reversals: the rigid-body controller does not compensate friction
    data = Trajectory(
        trajectory.t[moving], trajectory.q[moving], trajectory.v[moving], trajectory.a[moving], trajectory.tau[moving],
        list(plant.joint_names), plant.name,
    )  # fmt: skip
    base = base_parameters(plant, friction=True)
    for method in ("ls", "physical"):
        result = identify(plant, data, method=method, base=base)
        found = dict(zip(result.base.names, result.values, strict=True))
        np.testing.assert_allclose(
            [found[n] for n in ("fv[joint1]", "fv[joint2]", "fc[joint1]", "fc[joint2]")], [0.3, 2.0, 0.8, 1.5], rtol=1e-4
        )
        np.testing.assert_allclose(result.values, base.values, rtol=1e-4, atol=1e-5)  # physical: solver precision
    written = robodyn.load(identified_urdf(plant, result.standard, base.columns))
    np.testing.assert_allclose(written.joint_damping, [0.3, 2.0], rtol=1e-4)
    np.testing.assert_allclose(written.joint_friction, [0.8, 1.5], rtol=1e-4)
    # Negative controls: without the friction columns, or with the armature forgotten, the data are not explained.
    assert identify(plant, data).relative_error > 1e-3
    forgot = robodyn.load(text)  # the same robot without its armature
    assert identify(forgot, data, base=base_parameters(forgot, friction=True)).relative_error > 1e-6
