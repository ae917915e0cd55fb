"""Exact derivation, simplification a person accepts, parameters for every robot."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.cli.app import main
from robodyn.equations import derive_equations, render
from robodyn.equations.derive import substitute_parameters
from robodyn.equations.model import numeric
from robodyn.equations.simplify import chop
from robodyn.exceptions import InputError
from tests.equations.derived import derived

RRP = str(Path(__file__).parents[1] / "data" / "rrp_arm.urdf")
CLOSED = ["rp_arm", "double_pendulum", RRP]


def relative(a, b) -> float:
    return float(np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b))))


def coefficients(expr: sp.Expr) -> list[float]:
    expanded = sp.expand(numeric(expr))
    return [abs(float(term.as_coeff_Mul()[0])) for term in sp.Add.make_args(expanded) if expanded != 0]


@pytest.mark.parametrize("name", CLOSED, ids=["rp_arm", "double_pendulum", "rrp_arm"])
def test_no_round_off_terms_in_closed_forms(name):
    equations = derived(name)
    for entry in (*equations.M, *equations.Cv, *equations.G, *equations.C):
        sizes = coefficients(entry)
        if sizes:
            assert min(sizes) >= 1e-12 * max(sizes), entry


def test_chop_removes_round_off_and_keeps_the_rest():
    x = sp.Symbol("x")
    assert chop(3 * x + sp.Float(1e-20) * x**2 + 1) == 3 * x + 1
    assert chop(3 * x + sp.Rational(1, 10**9) * x**2) == 3 * x + sp.Rational(1, 10**9) * x**2


def test_double_pendulum_inertia_of_the_last_link_is_constant():
    """Round-off made M22 depend on q1 (impossible for a serial chain); exact numbers do not."""
    equations = derived("double_pendulum")
    assert equations.M[1, 1].free_symbols == set()
    assert equations.q[0] not in equations.M.free_symbols


def test_text_has_short_numbers_and_no_unit_coefficients(capsys):
    assert main(["equations", RRP, "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert not re.search(r"\d\.\d{7,}", out) and "1.0*" not in out
    assert "0.41*" in out or "+ 0.41" in out or "0.205" in out  # 0.4 + 0.01: written exactly
    assert main(["equations", "rp_arm", "--symbolic", "--precision", "3"]) == 0
    out = capsys.readouterr().out
    assert "0.181" in out and "0.180625" not in out  # (q2 + 0.7)² + 0.180625


def test_rrp_arm_reads_like_a_hand_derivation():
    equations = derived(RRP)
    _q1, q2, q3 = equations.q
    qd1, qd2, _qd3 = equations.qd
    r = q3 + sp.Rational(41, 100)  # the slider's centre of mass beyond the elbow, x and z offsets
    expected_M11 = (sp.Rational(1, 2) * r**2 + sp.Rational(2961, 20000) - sp.Rational(1681, 20000)) * sp.cos(
        q2
    ) ** 2 + sp.Rational(13, 1000)
    assert sp.expand(equations.M[0, 0] - expected_M11) == 0
    assert sp.expand(equations.Cv[2] + r / 2 * (qd2**2 + qd1**2 * sp.cos(q2) ** 2)) == 0
    assert equations.operation_count() <= 120


def test_compact_forms_meet_the_size_targets_without_copy_lines():
    equations = derived("ur5")
    assert equations.operation_count() <= 760
    assert not [s for s, e in equations.assignments if e.is_Symbol or e.is_Number]  # no `a = b`
    expressions = [e for _, e in equations.assignments]
    assert len(set(expressions)) == len(expressions)  # nothing assigned twice


@pytest.mark.slow
def test_panda_arm_meets_the_size_target():
    assert derive_equations("panda", lock={"panda_finger_joint1": 0.0}).operation_count() <= 1700


@pytest.mark.parametrize(
    ("name", "form"),
    [("rp_arm", "closed"), pytest.param(RRP, "closed", marks=pytest.mark.slow), (RRP, "compact"), ("ur5", "compact")],
    ids=str,
)
def test_kept_parameters_for_every_robot_give_the_robots_numbers(name, form, rng):
    equations = derive_equations(name, form=form, keep_params=True)
    kinds = {label[0] for label in equations.labels.values()}
    assert {"m", "c", "I", "g"} <= kinds
    owners = {label[1] for label in equations.labels.values()}
    robot = robodyn.load(name)
    assert owners - {""} <= set(robot.frame_names)  # named after links and joints
    with pytest.raises(InputError, match="code needs numbers"):
        render(equations, "python")
    namespace: dict = {}
    exec(render(substitute_parameters(equations), "python"), namespace)
    q = robot.random_configuration(rng, 10)
    v, a = rng.normal(size=(2, 10, robot.nv))
    assert relative(namespace["inverse_dynamics"](q, v, a), robot.inverse_dynamics(q, v, a)) < 1e-9


@pytest.mark.parametrize("name", ["rp_arm", RRP], ids=["rp_arm", "rrp_arm"])
def test_christoffel_symbols_rebuild_the_coriolis_matrix(name, capsys):
    from robodyn.equations.christoffel import christoffel_symbols

    equations = derived(name)
    gamma = christoffel_symbols(equations)
    n = len(equations.q)
    C = sp.zeros(n, n)
    for (i, j, k), value in gamma.items():
        C[i, j] += value * equations.qd[k]
        if j != k:
            C[i, k] += value * equations.qd[j]
    assert sp.expand(sp.expand_trig(C - equations.C)) == sp.zeros(n, n)
    assert main(["equations", name, "--symbolic", "--christoffel"]) == 0
    assert "Gamma[1," in capsys.readouterr().out
    with pytest.raises(InputError, match="closed"):
        christoffel_symbols(derive_equations(name, form="compact"))


ROTATED_ARM = """<?xml version="1.0"?>
<robot name="rotated_arm">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.1 0 0.05" rpy="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.012" iyz="0" izz="0.008"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.15 {offset} 0" rpy="0 0 0"/><mass value="0.8"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.009"/></inertial></link>
  <joint name="shoulder_pan" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="20" velocity="2"/></joint>
  <joint name="shoulder_pitch" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.2 0 0.05" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
</robot>
"""


def _matrix_coefficients(equations) -> dict[str, list[float]]:
    return {name: [c for e in getattr(equations, name) for c in coefficients(e)] for name in ("M", "C", "Cv", "G")}


@pytest.mark.parametrize("offset", ["0", "1e-9"], ids=["round_off_only", "genuine_small_term"])
def test_a_rotated_joint_origin_leaves_no_round_off_and_keeps_real_small_terms(offset, tmp_path, rng):
    """The rationals of a 0.3 rad rotation are orthonormal to ~1e-16 only: sin² + cos² = 1
    left ``3.8e-18 cos(q)²`` in M[2,2] and a C[2,2] of round-off alone. A centre of mass
    1e-9 m off the plane is a real term ~1e-9 of the largest and stays."""
    path = tmp_path / "rotated_arm.urdf"
    path.write_text(ROTATED_ARM.format(offset=offset))
    equations = derive_equations(path)
    assert equations.form == "closed"
    sizes = _matrix_coefficients(equations)
    for name, found in sizes.items():
        largest = max(found + (sizes["M"] if name in ("C", "Cv") else []))
        assert min(found) >= 1e-12 * largest, name
    smallest = min(sizes["M"]) / max(sizes["M"])
    assert (smallest < 1e-6) == (offset != "0")  # the genuine term is kept
    assert equations.M[1, 1].free_symbols == set() and equations.C[1, 1] == 0
    robot = robodyn.load(path)
    namespace: dict = {}
    exec(render(equations, "python"), namespace)
    q = robot.random_configuration(rng, 10)
    v, a = rng.normal(size=(2, 10, robot.nv))
    assert relative(namespace["inverse_dynamics"](q, v, a), robot.inverse_dynamics(q, v, a)) < 1e-9
    for k in range(3):
        assert relative(numeric_matrix(equations.M, equations.q, q[k]), robot.mass_matrix(q[k])) < 1e-9


def numeric_matrix(matrix: sp.Matrix, symbols, values) -> np.ndarray:
    return np.array(sp.lambdify(symbols, matrix, "numpy")(*values), dtype=float)


def test_chop_with_a_floor_drops_only_what_is_below_it():
    x = sp.Symbol("x")
    assert chop(sp.Rational(1, 10**17) * sp.cos(x) ** 2, 1e-14) == 0
    assert chop(sp.Rational(1, 10**13) * sp.cos(x) ** 2 + 2, 1e-14) == sp.Rational(1, 10**13) * sp.cos(x) ** 2 + 2
