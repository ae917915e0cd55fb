"""Issue 13, item 8 (reference and sampling): floating robots in the reference's forward
dynamics and kinetic energy; placeholder limits sampled in a physical range.

Reproductions: ``reference.forward_dynamics`` / ``kinetic_energy`` sized ``q`` by ``nv``
and refused every floating robot; ``random_configuration`` drew ridgeback-style ±999 999
limits as real positions, so ``check`` failed a correct model; ``random_configuration(rng,
-1)`` was not an InputError.

Also here:

- The independent reference: no Pinocchio inside, and agreement with Pinocchio.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn
import robodyn.reference as reference
from robodyn.exceptions import InputError
from robodyn.reference import rp_closed_form as closed
from robodyn.reference.symbolic import derive
from robodyn.urdf.models import RPArmParameters, rp_arm_urdf
from robodyn.verify.check import check_robot
from tests.conftest import FAST_ZOO, ROOT, URDF_FILES


def reference_order(robot, model):
    joints = robot.joint_names[1:]
    others = model.joint_names[1:]
    v_order = list(range(6)) + [6 + others.index(name) for name in joints]
    q_order = list(range(7)) + [7 + others.index(name) for name in joints]
    return q_order, v_order


def to_reference(x, order):
    out = np.empty_like(x)
    out[:, order] = x
    return out


def test_reference_forward_dynamics_and_kinetic_energy_take_floating_robots():
    robot = robodyn.load("solo12")
    model = reference.load("solo12", floating_base=True)
    q_order, v_order = reference_order(robot, model)
    rng = np.random.default_rng(5)
    q, v, tau = robot.random_configuration(rng, 6), rng.normal(size=(6, 18)), rng.normal(size=(6, 18))
    mine = robot.forward_dynamics(q, v, tau)
    theirs = model.forward_dynamics(to_reference(q, q_order), to_reference(v, v_order), to_reference(tau, v_order))[:, v_order]
    np.testing.assert_allclose(theirs, mine, rtol=1e-9, atol=1e-9 * np.abs(mine).max())
    energy = model.kinetic_energy(to_reference(q, q_order), to_reference(v, v_order))
    np.testing.assert_allclose(energy, robot.kinetic_energy(q, v), rtol=1e-12)
    single = model.kinetic_energy(to_reference(q, q_order)[0], to_reference(v, v_order)[0])
    assert single == pytest.approx(energy[0], rel=1e-14)
    # Negative control: a wrong torque gives other accelerations.
    wrong = model.forward_dynamics(to_reference(q, q_order), to_reference(v, v_order), to_reference(tau + 0.1, v_order))
    assert np.abs(wrong[:, v_order] - mine).max() > 1e-3


PLACEHOLDER = """<robot name="placeholder_base">
  <link name="world"/>
  <joint name="rail" type="prismatic"><parent link="world"/><child link="cart"/><axis xyz="0.6 0.8 0"/>
    <limit lower="-999999" upper="999999" effort="100" velocity="1"/></joint>
  <link name="cart"><inertial><origin xyz="0.05 0 0.1"/><mass value="3"/>
    <inertia ixx="0.1" ixy="0.01" ixz="0" iyy="0.2" iyz="0" izz="0.15"/></inertial></link>
  <joint name="turn" type="revolute"><parent link="cart"/><child link="arm"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1e4" upper="1e4" effort="100" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0.3 0 0"/><mass value="1.2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.04"/></inertial></link>
  <joint name="lift" type="revolute"><parent link="arm"/><child link="hand"/><origin xyz="0.6 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="999999" effort="20" velocity="1"/></joint>
  <link name="hand"><inertial><origin xyz="0.1 0 0"/><mass value="0.4"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
</robot>"""


def test_placeholder_limits_are_sampled_in_a_physical_range():
    robot = robodyn.load(PLACEHOLDER)
    q = robot.random_configuration(np.random.default_rng(0), 2000)
    assert np.abs(q[:, :2]).max() <= np.pi  # no limit: [-π, π]
    assert q[:, 2].min() >= -2 and q[:, 2].max() <= -2 + 2 * np.pi  # one limit: 2π on its side
    assert np.ptp(q[:, 0]) > 5  # and really spread over it
    lower, upper = robot.physical_limits()
    assert np.isinf(lower[:2]).all() and lower[2] == -2 and np.isinf(upper).all()


def test_check_passes_a_correct_model_with_placeholder_limits():
    robot = robodyn.load(PLACEHOLDER)
    assert check_robot(robot, samples=20, seed=1).passed


@pytest.mark.parametrize("count", [-1, 2.5, "3", True])
def test_random_configuration_refuses_a_bad_count(count):
    with pytest.raises(InputError, match="count"):
        robodyn.load("ur5").random_configuration(np.random.default_rng(0), count)


def test_random_configuration_of_zero_states_is_empty():
    assert robodyn.load("ur5").random_configuration(np.random.default_rng(0), 0).shape == (0, 6)


def test_empty_limit_ranges_are_no_limits():
    """The zoo's double pendulum writes lower = upper = 0 on joints that swing freely: its
    states must not all be q = 0, and a swing is not a limit violation."""
    import warnings

    from robodyn.sim.simulation import simulate

    robot = robodyn.load("double_pendulum")
    assert np.ptp(robot.random_configuration(np.random.default_rng(0), 100), axis=0).min() > 3
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        trajectory = simulate(robot, np.array([1.0, 0.5]), np.zeros(2), 0.5, 1e-3)
    assert np.ptp(trajectory.q[:, 0]) > 0.1


REFERENCE_DIR = ROOT / "robodyn" / "reference"


def imported_modules(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def test_no_module_of_the_reference_imports_pinocchio():
    for path in REFERENCE_DIR.glob("*.py"):
        modules = imported_modules(path)
        assert not {m for m in modules if m.split(".")[0] in ("pinocchio", "coal", "hppfcl")}, path
        # Nor robodyn modules that do (loading, robot, check, cli).
        assert not modules & {"robodyn.dynamics.loading", "robodyn.dynamics.robot", "robodyn.verify.check", "robodyn.cli.app"}, (
            path
        )


def test_reference_runs_in_a_process_where_pinocchio_cannot_be_imported():
    program = """
import sys
class Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('pinocchio', 'coal', 'hppfcl', 'cmeel'):
            raise ImportError('pinocchio is forbidden here: ' + name)
sys.meta_path.insert(0, Refuse())
from robodyn import reference
robot = reference.load('panda')
tau = robot.inverse_dynamics([0.1] * 8, [0.2] * 8, [0.3] * 8)
assert tau.shape == (8,)
assert not any(name.split('.')[0] == 'pinocchio' for name in sys.modules)
print('ok')
"""
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


@pytest.mark.parametrize("source", [str(p) for p in URDF_FILES] + FAST_ZOO + [str(ROOT / "tests" / "data" / "gantry.urdf")])
def test_pinocchio_agrees_with_the_reference(source):
    report = check_robot(source, samples=40, seed=1)
    assert report.passed, {name: c.max_rel for name, c in report.comparisons.items()}


@pytest.mark.parametrize("parameters", [RPArmParameters(), RPArmParameters(l1=0.9, m1=1.2, m2=2.5, l2=0.3, Iz1=0.2)])
def test_reference_matches_the_hand_written_rp_closed_form(parameters, rng):
    model = reference.load(rp_arm_urdf(parameters))
    assert model.joint_names == ["joint1", "joint2"]
    q = np.column_stack([rng.uniform(-3, 3, 100), rng.uniform(0, 0.3, 100)])
    v, a = rng.normal(size=(2, 100, 2))
    np.testing.assert_allclose(model.mass_matrix(q), closed.mass_matrix(parameters, q), atol=1e-13)
    np.testing.assert_allclose(model.coriolis_matrix(q, v), closed.coriolis_matrix(parameters, q, v), atol=1e-13)
    np.testing.assert_allclose(model.gravity(q), closed.gravity(parameters, q), atol=1e-12)
    np.testing.assert_allclose(model.inverse_dynamics(q, v, a), closed.inverse_dynamics(parameters, q, v, a), atol=1e-12)
    np.testing.assert_allclose(model.potential_energy(q), closed.potential_energy(parameters, q), atol=1e-12)


def test_mass_matrix_derivative_matches_finite_differences(rng):
    model = reference.load("ur5")
    q, v = rng.uniform(-2, 2, 6), rng.normal(size=6)
    step = 1e-6
    numeric = (model.mass_matrix(q + step * v) - model.mass_matrix(q - step * v)) / (2 * step)
    np.testing.assert_allclose(model.mass_matrix_derivative(q, v), numeric, atol=1e-8)


def test_joints_are_matched_by_name_when_orders_differ():
    """Two branches whose document order is not alphabetical: Pinocchio and yourdfpy disagree on
    the order, and check must still match joint to joint."""
    urdf = (ROOT / "tests" / "data" / "two_branches.urdf").read_text()
    robot, model = robodyn.load(urdf), reference.load(urdf)
    assert set(robot.joint_names) == set(model.joint_names)
    report = check_robot(robot, samples=20)
    assert report.passed


def test_symbolic_derivation_matches_the_numeric_reference(rng):
    model = reference.load("double_pendulum_continuous")
    equations = derive(model)
    tau = sp.lambdify([equations.q, equations.qd, equations.qdd], equations.tau, "numpy")
    for _ in range(5):
        q, v, a = rng.normal(size=(3, 2))
        np.testing.assert_allclose(np.ravel(tau(q, v, a)), model.inverse_dynamics(q, v, a), rtol=1e-9, atol=1e-12)


def test_symbolic_rp_arm_is_the_hand_written_closed_form():
    equations = derive(reference.load("rp_arm"))
    p = RPArmParameters()
    q1, q2 = equations.q
    qd1, qd2 = equations.qd
    r2 = p.l1 + q2 + p.c2
    expected_M = sp.Matrix([[p.m1 * p.l1**2 / 4 + p.inertia1 + p.m2 * r2**2 + p.inertia2, 0], [0, p.m2]])
    expected_G = sp.Matrix([(p.m1 * p.l1 / 2 + p.m2 * r2) * 9.81 * sp.cos(q1), p.m2 * 9.81 * sp.sin(q1)])
    expected_Cv = sp.Matrix([2 * p.m2 * r2 * qd1 * qd2, -p.m2 * r2 * qd1**2])
    for difference in (equations.M - expected_M, equations.G - expected_G, equations.C * sp.Matrix(equations.qd) - expected_Cv):
        for entry in sp.expand(difference):
            assert all(
                abs(float(c)) < 1e-12 for c in sp.Poly(entry, *equations.q, *equations.qd, sp.sin(q1), sp.cos(q1)).coeffs()
            )


def test_euler_lagrange_from_the_energies_equals_m_c_g():
    equations = derive(reference.load("rp_arm"))
    q1 = equations.q[0]
    residual = sp.expand(sp.expand(equations.euler_lagrange() - equations.tau).subs(sp.sin(q1) ** 2, 1 - sp.cos(q1) ** 2))
    for entry in residual:
        if entry != 0:
            assert all(
                abs(float(c)) < 1e-12 for c in sp.Poly(entry, *equations.q, *equations.qd, *equations.qdd, sp.cos(q1)).coeffs()
            )


@pytest.mark.parametrize(("name", "floating"), [("panda", False), ("solo12", True)])
def test_every_term_in_one_pass_equals_each_method(name, floating):
    model = reference.load(robodyn.load(name).urdf, floating_base=floating)
    robot = robodyn.load(name)
    rng = np.random.default_rng(3)
    q = robot.random_configuration(rng, 7)  # not a multiple of the chunk
    v, a = rng.normal(size=(7, model.nv)), rng.normal(size=(7, model.nv))
    terms = model.terms(q, v, a)
    methods = {
        "tau": model.inverse_dynamics(q, v, a), "M": model.mass_matrix(q), "Cv": model.coriolis_forces(q, v),
        "G": model.gravity(q),
    }  # fmt: skip
    if not floating:
        methods |= {"C": model.coriolis_matrix(q, v), "Mdot": model.mass_matrix_derivative(q, v)}
    assert set(terms) == set(methods)
    for key, value in methods.items():
        np.testing.assert_array_equal(terms[key], value)
