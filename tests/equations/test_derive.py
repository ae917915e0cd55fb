"""Symbolic equations: right against the hand form, the lecture, Pinocchio; code that runs."""

from __future__ import annotations

import ctypes
import importlib.util
import json
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings

import robodyn
from robodyn.cli.app import main
from robodyn.equations import lecture
from robodyn.equations.derive import derive_equations, render
from tests.random_robots import random_urdfs

PANDA_ARM = {"panda_finger_joint1": 0.0}
CODE_ROBOTS = [
    ("double_pendulum", None),
    ("rp_arm", None),
    ("ur5", None),
    pytest.param("panda", PANDA_ARM, marks=pytest.mark.slow),
]


def test_rp_arm_with_kept_parameters_is_the_hand_derived_rigid_form():
    generic = derive_equations("rp_arm", keep_params=True)
    assert {str(s) for s in generic.parameters} == {
        "m_link1",
        "c_link1_x",
        "I_link1_yy",
        "d_joint2_x",
        "m_link2",
        "c_link2_x",
        "I_link2_yy",
        "g",
    }
    equations = lecture.in_lecture_symbols(generic)
    rigid = lecture.rigid()
    rename = {equations.q[0]: lecture.q1, equations.q[1]: lecture.q2, equations.qd[0]: lecture.qd1, equations.qd[1]: lecture.qd2}
    assert sp.simplify(equations.M.xreplace(rename) - rigid.M) == sp.zeros(2, 2)
    assert sp.simplify(equations.C.xreplace(rename) - rigid.C) == sp.zeros(2, 2)
    assert sp.simplify(equations.G.xreplace(rename) - rigid.G) == sp.zeros(2, 1)
    assert {str(s) for s in equations.parameters} == {"l1", "m1", "m2", "Iz1", "Iz2", "c2", "g"}


def test_exact_zeros_print_as_zero(capsys):
    assert main(["equations", "rp_arm", "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert "M[1,2] = 0\n" in out and "C[2,2] = 0\n" in out


def load_module(path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def relative(a, b):
    return float(np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b))))


@pytest.mark.parametrize(("name", "lock"), CODE_ROBOTS, ids=["double_pendulum", "rp_arm", "ur5", "panda"])
def test_generated_python_agrees_with_pinocchio(name, lock, tmp_path, rng):
    path = tmp_path / f"{name}_dynamics.py"
    path.write_text(render(derive_equations(name, lock=lock), "python"))
    module = load_module(path)
    robot = robodyn.load(name, lock=lock)
    assert robot.joint_names == module.JOINT_NAMES or sorted(module.JOINT_NAMES) == sorted(robot.joint_names)
    order = [module.JOINT_NAMES.index(j) for j in robot.joint_names]
    q = robot.random_configuration(rng, 50)
    v, a = rng.normal(size=(2, 50, robot.nv))
    to_module = np.empty_like(q)
    to_module[:, order] = q
    vm, am = np.empty_like(v), np.empty_like(a)
    vm[:, order], am[:, order] = v, a
    back = np.ix_(order, order)
    assert relative(module.mass_matrix(to_module)[:, back[0], back[1]], robot.mass_matrix(q)) < 1e-9
    assert relative(module.gravity(to_module)[:, order], robot.gravity(q)) < 1e-9
    assert relative(module.coriolis_matrix(to_module, vm)[:, back[0], back[1]], robot.coriolis_matrix(q, v)) < 1e-9
    assert relative(module.inverse_dynamics(to_module, vm, am)[:, order], robot.inverse_dynamics(q, v, a)) < 1e-9
    # One state at a time gives the same as the stack.
    np.testing.assert_allclose(
        module.inverse_dynamics(to_module[3], vm[3], am[3]), module.inverse_dynamics(to_module, vm, am)[3], rtol=1e-12
    )


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs a C compiler")
@pytest.mark.parametrize(
    ("name", "lock"), [("ur5", None), pytest.param("panda", PANDA_ARM, marks=pytest.mark.slow)], ids=["ur5", "panda"]
)
def test_generated_c_compiles_and_agrees_with_pinocchio(name, lock, tmp_path, rng):
    source, library = tmp_path / "dynamics.c", tmp_path / "libdynamics.so"
    source.write_text(render(derive_equations(name, lock=lock), "c"))
    subprocess.run(
        ["gcc", "-std=c99", "-O2", "-Wall", "-Werror", "-shared", "-fPIC", str(source), "-o", str(library), "-lm"], check=True
    )
    lib = ctypes.CDLL(str(library))
    robot = robodyn.load(name, lock=lock)
    n = robot.nv
    pointer = ctypes.POINTER(ctypes.c_double)
    for _ in range(20):
        q = robot.random_configuration(rng)
        v, a = rng.normal(size=(2, n))
        tau, M, C = np.zeros(n), np.zeros(n * n), np.zeros(n * n)
        lib.inverse_dynamics(*(x.ctypes.data_as(pointer) for x in (q, v, a, tau)))
        lib.mass_matrix(q.ctypes.data_as(pointer), M.ctypes.data_as(pointer))
        lib.coriolis_matrix(q.ctypes.data_as(pointer), v.ctypes.data_as(pointer), C.ctypes.data_as(pointer))
        assert relative(tau, robot.inverse_dynamics(q, v, a)) < 1e-9
        assert relative(M.reshape(n, n), robot.mass_matrix(q)) < 1e-9
        assert relative(C.reshape(n, n), robot.coriolis_matrix(q, v)) < 1e-9


def test_compact_form_is_small_and_fast_for_ur5():
    equations = derive_equations("ur5")
    assert equations.form == "compact"
    assert equations.operation_count() <= 760


def test_json_round_trips_through_sympy(rng, capsys):
    assert main(["equations", "double_pendulum", "--symbolic", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    symbols = {name: sp.Symbol(name, real=True) for name in data["q"] + data["qd"]}
    G = [sp.sympify(e, locals=symbols) for e in data["G"]]
    robot = robodyn.load("double_pendulum")
    q = rng.uniform(-1, 1, 2)
    values = [float(g.subs({symbols[data["q"][0]]: q[0], symbols[data["q"][1]]: q[1]})) for g in G]
    assert relative(np.array(values), robot.gravity(q)) < 1e-9


def test_latex_is_a_complete_document(capsys, tmp_path):
    assert main(["equations", "rp_arm", "--symbolic", "--format", "latex", "--keep-params"]) == 0
    tex = capsys.readouterr().out
    assert tex.startswith(r"\documentclass") and tex.rstrip().endswith(r"\end{document}")
    assert tex.count(r"\begin{align*}") == tex.count(r"\end{align*}") and tex.count("{") == tex.count("}")
    assert r"\dot q_{1}" in tex and r"m_{\text{link1}}" in tex and "qd_" not in tex
    if shutil.which("pdflatex"):
        from robodyn.equations.render_latex import compile_latex

        pdf, log = compile_latex(tex, tmp_path)
        assert pdf.read_bytes().startswith(b"%PDF") and "Overfull" not in log


def test_progress_goes_to_stderr_and_json_stays_clean(capsys, monkeypatch):

    import robodyn.cli.common as cli_common

    monkeypatch.setattr(cli_common.Progress, "DELAY", 0.0)
    monkeypatch.setattr(cli_common, "_is_terminal", lambda stream: True)  # progress only on a terminal
    monkeypatch.setattr(cli_common, "_is_terminal", lambda stream: True)  # progress only on a terminal
    assert main(["equations", "ur5", "--symbolic", "--format", "json"]) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    assert "deriving ur5" in captured.err and "[" in captured.err


def test_lecture_mode_names_the_errata(capsys):
    assert main(["equations", "rp_arm", "--lecture"]) == 0
    out = capsys.readouterr().out
    assert "as printed (slide 34)" in out and "corrected" in out and "rigid body" in out
    assert "1. potential energy sign" in out and "3. not a rigid body" in out


def test_out_file_is_written_only_on_success(tmp_path, capsys):
    target = tmp_path / "eq.py"
    target.write_text("keep me")
    assert main(["equations", "no_such_robot", "--symbolic", "--out", str(target)]) == 2
    assert target.read_text() == "keep me"
    assert main(["equations", "rp_arm", "--symbolic", "--format", "python", "--out", str(target)]) == 0
    assert "def inverse_dynamics" in target.read_text()


@pytest.mark.slow  # a property over random trees, 7 s
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_compact_form_of_random_trees_agrees_with_pinocchio(urdf):
    namespace: dict = {}
    exec(render(derive_equations(urdf, form="compact"), "python"), namespace)
    robot = robodyn.load(urdf)
    order = [namespace["JOINT_NAMES"].index(j) for j in robot.joint_names]
    rng = np.random.default_rng(5)
    q = robot.random_configuration(rng, 10)
    v, a = rng.normal(size=(2, 10, robot.nv))
    to_module = [np.empty_like(x) for x in (q, v, a)]
    for target, source in zip(to_module, (q, v, a), strict=True):
        target[:, order] = source
    assert relative(namespace["inverse_dynamics"](*to_module)[:, order], robot.inverse_dynamics(q, v, a)) < 1e-9


def test_floating_robots_need_an_explicit_fixed_base(capsys):
    assert main(["equations", "solo12", "--symbolic"]) == 2
    assert "symbolic equations model fixed bases (--fixed-base)" in capsys.readouterr().err
    assert main(["equations", "solo12", "--symbolic", "--fixed-base", "--format", "json"]) == 0
    assert len(json.loads(capsys.readouterr().out)["joint_names"]) == 12


# A 3-DoF arm (revolute, revolute, prismatic) whose wrist mimics the elbow, its origin
# turned by 0.3 rad: estimated 15 s before issue 29, its closed form takes minutes.
SLOW_MIMIC_ARM = """<?xml version="1.0"?>
<robot name="slow_mimic">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.1 0 0.05" rpy="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.008"/></inertial></link>
  <link name="middle"><inertial><origin xyz="0.15 0.01 0" rpy="0 0 0"/><mass value="0.8"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.008"/></inertial></link>
  <link name="ram"><inertial><origin xyz="0.05 0 0" rpy="0 0 0"/><mass value="0.5"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.008"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0.05 0 0.02" rpy="0 0 0"/><mass value="0.3"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.008"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="20" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="middle"/>
    <origin xyz="0.2 0 0.05" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="2"/></joint>
  <joint name="extend" type="prismatic"><parent link="middle"/><child link="ram"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.1" upper="0.1" effort="20" velocity="2"/></joint>
  <joint name="wrist" type="revolute"><parent link="ram"/><child link="tip"/>
    <origin xyz="0.1 0 0" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="2"/>
    <mimic joint="elbow" multiplier="-1.5" offset="0.2"/></joint>
</robot>
"""


def _never_closed(*args, **kwargs):
    raise AssertionError("the closed-form Lagrangian was derived")


def test_a_slow_mimic_arm_in_auto_form_is_derived_compact_and_says_so(tmp_path, monkeypatch, rng):
    import time

    from robodyn.equations import derive as derive_module

    path = tmp_path / "slow_mimic.urdf"
    path.write_text(SLOW_MIMIC_ARM)
    monkeypatch.setattr(derive_module, "derive", _never_closed)
    start = time.perf_counter()
    equations = derive_equations(path)
    assert time.perf_counter() - start < 30
    assert equations.form == "compact"
    robot = robodyn.load(path)
    namespace: dict = {}
    exec(render(equations, "python"), namespace)
    q = robot.random_configuration(rng, 5)
    v, a = rng.normal(size=(2, 5, robot.nv))
    tau = robot.inverse_dynamics(q, v, a)
    assert np.max(np.abs(namespace["inverse_dynamics"](q, v, a) - tau)) < 1e-9 * max(1.0, np.max(np.abs(tau)))


def test_a_slow_closed_form_is_refused_in_one_line_before_any_work(tmp_path, monkeypatch, capsys):
    from robodyn.equations import derive as derive_module
    from robodyn.exceptions import DerivationTooExpensiveError

    path = tmp_path / "slow_mimic.urdf"
    path.write_text(SLOW_MIMIC_ARM)
    monkeypatch.setattr(derive_module, "derive", _never_closed)
    with pytest.raises(DerivationTooExpensiveError, match="form='compact'") as refused:
        derive_equations(path, form="closed")
    assert refused.value.estimate_s > refused.value.limit_s and "\n" not in str(refused.value)
    assert main(["equations", str(path), "--symbolic", "--form", "closed"]) == 2
    err = capsys.readouterr().err
    assert "--form compact" in err and len(err.strip().splitlines()) == 1
