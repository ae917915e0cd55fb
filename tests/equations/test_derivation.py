"""The Lagrangian worked step by step: every step checked against Pinocchio at random states.

Each check has a negative control: the same comparison with one known mistake (a link left
out, the joint frame instead of the centre of mass, the velocity products dropped, ``C``
transposed, another state) must fail it by far.
"""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import sympy as sp

import robodyn
from robodyn.cli.app import main
from robodyn.equations import lecture
from robodyn.equations.render_derivation import (
    Derivation,
    derivation,
    derivation_document,
    latex_math,
    render_derivation,
    to_dict,
    to_latex,
    to_text,
)
from robodyn.equations.render_latex import compile_latex
from robodyn.exceptions import InputError

DATA = Path(__file__).parent.parent / "data"
SIDEWAYS = (1.5, -2.0, -9.0)
#: (id, source, gravity): the robots of the issue; the oblique slider under another gravity.
CASES = [
    ("rp_arm", "rp_arm", None),
    ("rrp_arm", str(DATA / "rrp_arm.urdf"), None),
    ("double_pendulum", str(DATA / "robots" / "double_pendulum.urdf"), None),
    ("oblique_slider", str(DATA / "robots" / "oblique_slider.urdf"), SIDEWAYS),
    ("mimic_arm", str(DATA / "mimic_arm.urdf"), None),
]
FAST = {"rp_arm"}
PARAMS = [pytest.param(case, id=case[0], marks=() if case[0] in FAST else pytest.mark.slow) for case in CASES]
TOLERANCE = 1e-9
#: A negative control must be off by more than this (relative): a thousand times the tolerance.
MISTAKE = 1e-6


@cache
def derived(source: str, gravity: tuple | None, keep_params: bool = False) -> Derivation:
    return derivation(source, gravity=gravity, keep_params=keep_params)


@cache
def robot_of(source: str, gravity: tuple | None):
    return robodyn.load(source, gravity=gravity)


def numeric(steps: Derivation, expr, q: np.ndarray, v: np.ndarray | None = None, a: np.ndarray | None = None) -> np.ndarray:
    """``expr`` (scalar or matrix) at one state, kept parameters replaced by their values."""
    expr = sp.sympify(expr).xreplace({s: sp.Float(value) for s, value in steps.parameters.items()})
    symbols = [*steps.q, *steps.qd, *steps.qdd]
    n = len(steps.q)
    values = [*q, *(np.zeros(n) if v is None else v), *(np.zeros(n) if a is None else a)]
    return np.array(sp.lambdify(symbols, expr, "numpy")(*values), dtype=float)


def relative(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def states(robot, count: int = 5, seed: int = 7):
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng, count)
    v, a = rng.normal(size=(2, count, robot.nv))
    return list(zip(q, v, a, strict=True))


def centres_of_mass(robot, q: np.ndarray) -> dict[str, np.ndarray]:
    """Each moving joint's body centre of mass (and joint origin) in the world, from Pinocchio."""
    model, data, full_q = (
        (robot.model, robot.data, q) if robot.mimic is None else (robot.mimic.model, robot.mimic.data, robot.mimic.q(q))
    )
    pin.forwardKinematics(model, data, full_q)
    return {
        model.names[j]: (data.oMi[j].act(model.inertias[j].lever), data.oMi[j].translation.copy())
        for j in range(1, model.njoints)
    }


# Worst errors of every check, printed at the end of the module (pytest -s) for the report.
WORST: dict[str, float] = {}


def record(check: str, error: float) -> float:
    WORST[check] = max(WORST.get(check, 0.0), error)
    return error


@pytest.fixture(scope="module", autouse=True)
def report_worst():
    yield
    for check, error in sorted(WORST.items()):
        print(f"\nworst {check}: {error:.2e}")


@pytest.mark.parametrize("case", PARAMS)
def test_each_link_energy_sums_to_the_robots_energy(case):
    _name, source, gravity = case
    steps, robot = derived(source, gravity), robot_of(source, gravity)
    potential_offsets, without_last = [], []
    for q, v, _ in states(robot):
        T = sum(numeric(steps, link.T, q, v) for link in steps.links)
        assert record("T", relative(T, robot.kinetic_energy(q, v))) < TOLERANCE
        U = [float(numeric(steps, link.U, q)) for link in steps.links]
        potential_offsets.append(sum(U) - robot.potential_energy(q))
        without_last.append(sum(U[:-1]) - robot.potential_energy(q))
        # Negative control: the last link left out.
        partial = sum(numeric(steps, link.T, q, v) for link in steps.links[:-1])
        assert relative(partial, robot.kinetic_energy(q, v)) > MISTAKE
    assert record("U (up to a constant)", float(np.ptp(potential_offsets))) < TOLERANCE
    assert np.ptp(without_last) > MISTAKE


@pytest.mark.parametrize("case", PARAMS)
def test_each_links_centre_of_mass_is_pinocchios(case):
    _name, source, gravity = case
    steps, robot = derived(source, gravity), robot_of(source, gravity)
    for q, _, _ in states(robot):
        pinocchio = centres_of_mass(robot, q)
        for link in steps.links:
            com, joint_origin = pinocchio[link.joint]
            p = numeric(steps, link.p, q).ravel()
            assert record("p", relative(p, com)) < TOLERANCE
            assert relative(p, joint_origin) > MISTAKE  # negative control: the lever forgotten


@pytest.mark.parametrize("case", PARAMS)
def test_each_joints_tau_is_the_inverse_dynamics(case):
    _name, source, gravity = case
    steps, robot = derived(source, gravity), robot_of(source, gravity)
    for q, v, a in states(robot):
        tau = numeric(steps, steps.tau, q, v, a).ravel()
        assert record("tau", relative(tau, robot.inverse_dynamics(q, v, a))) < TOLERANCE
        # Step 5 is d/dt dL/dqd - dL/dq, joint by joint.
        parts = [numeric(steps, j.ddt_dL_dqd - j.dL_dq, q, v, a) for j in steps.joints]
        assert relative(np.ravel(parts), tau) < TOLERANCE
        # Negative control: the velocity products dropped.
        without = tau - numeric(steps, steps.Cv, q, v).ravel()
        assert relative(without, robot.inverse_dynamics(q, v, a)) > MISTAKE


@pytest.mark.parametrize("case", PARAMS)
def test_the_matrix_form_is_pinocchios_M_C_and_G(case):
    _name, source, gravity = case
    steps, robot = derived(source, gravity), robot_of(source, gravity)
    for q, v, a in states(robot):
        M, C = numeric(steps, steps.M, q), numeric(steps, steps.C, q, v)
        assert record("M", relative(M, robot.mass_matrix(q))) < TOLERANCE
        assert record("C", relative(C, robot.coriolis_matrix(q, v))) < TOLERANCE
        assert record("C v", relative(numeric(steps, steps.Cv, q, v).ravel(), robot.coriolis_matrix(q, v) @ v)) < TOLERANCE
        assert record("G", relative(numeric(steps, steps.G, q).ravel(), robot.gravity(q))) < TOLERANCE
        tau = numeric(steps, steps.M * sp.Matrix(steps.qdd) + steps.Cv + steps.G, q, v, a).ravel()
        assert relative(tau, numeric(steps, steps.tau, q, v, a).ravel()) < TOLERANCE
        # Negative controls: another state's M and G, C transposed.
        other = q + 0.5
        assert relative(M, robot.mass_matrix(other)) > MISTAKE
        assert relative(numeric(steps, steps.G, q).ravel(), robot.gravity(other)) > MISTAKE
        assert relative(C.T @ v, robot.coriolis_matrix(q, v) @ v) > MISTAKE


@pytest.mark.slow
def test_sideways_gravity_is_the_one_derived_for():
    _name, source, gravity = CASES[3]
    steps, robot = derived(source, gravity), robot_of(source, None)
    q = states(robot)[0][0]
    assert steps.gravity == SIDEWAYS
    assert relative(numeric(steps, steps.G, q).ravel(), robot.gravity(q)) > MISTAKE


@pytest.mark.slow
def test_the_mimic_arms_bodies_follow_the_mimic_map():
    steps = derived(CASES[4][1], None)
    assert steps.joint_names == ("shoulder", "elbow") and [link.joint for link in steps.links][-1] == "wrist"
    wrist = steps.links[-1]
    assert wrist.R.has(steps.q[1]) and wrist.omega.has(steps.qd[1])
    assert not any("wrist" in str(s) for s in steps.L.free_symbols | steps.M.free_symbols)


@pytest.mark.slow
def test_kept_parameters_give_the_lectures_symbols_and_its_corrected_rigid_result():
    steps = derived("rp_arm", None, True)
    lecture_names = {"m1", "m2", "l1", "c2", "Iz1", "Iz2", "g"}
    names = {s.name for s in steps.parameters}
    assert lecture_names <= names and all(name.startswith("I_link") for name in names - lecture_names)
    assert not {s.name for s in steps.M.free_symbols} - lecture_names - {"q_joint2"}  # the lecture's M
    joint = dict(
        zip(
            [lecture.q1, lecture.q2, lecture.qd1, lecture.qd2, lecture.qdd1, lecture.qdd2],
            [*steps.q, *steps.qd, *steps.qdd],
            strict=True,
        )
    )
    rigid = lecture.rigid().tau.xreplace(joint)
    assert sp.simplify(steps.tau - rigid) == sp.zeros(2, 1)
    assert sp.simplify(steps.tau - lecture.printed().xreplace(joint)) != sp.zeros(2, 1)  # negative control
    # Numbers and symbols agree: the kept derivation at its values is the numeric one.
    robot = robot_of("rp_arm", None)
    for q, v, a in states(robot, 3):
        assert relative(numeric(steps, steps.tau, q, v, a).ravel(), robot.inverse_dynamics(q, v, a)) < TOLERANCE


def test_the_lectures_errata_are_marked_at_the_steps_they_enter():
    text = to_text(derived("rp_arm", None, True))
    steps = re.split(r"\nStep (\d)\.", text)
    marked = {int(steps[i]): re.findall(r"! erratum (\d)", steps[i + 1]) for i in range(1, len(steps), 2)}
    assert marked == {1: ["3"], 2: [], 3: ["1"], 4: [], 5: ["2"], 6: []}
    assert "as printed on slide 34" in text
    plain = to_text(derived(CASES[0][1], None))
    assert "erratum" in plain  # the numbers-only arm is still the lecture's
    data = to_dict(derived("rp_arm", None, True))
    assert [e["step"] for e in data["lecture"]["errata"]] == [3, 5, 1]


def test_json_carries_every_step_in_the_equations_naming():
    steps = derived("rp_arm", None)
    data = json.loads(render_derivation(steps, "json"))
    keys = ["p", "v", "omega", "T", "U", "L", "dL_dqd", "ddt_dL_dqd", "dL_dq", "tau", "M", "C", "G"]
    assert set(keys) <= set(data)
    assert data["q"] == ["q_joint1", "q_joint2"] and data["qdd"] == ["qdd_joint1", "qdd_joint2"]
    names = {s.name: s for s in [*steps.q, *steps.qd, *steps.qdd]}
    for key, mine in [("L", steps.L), ("tau", steps.tau), ("T", steps.links[1].T)]:
        value = data[key] if key == "L" else (data[key] if key == "tau" else data[key][1])
        back = sp.Matrix(sp.sympify(value, locals=names)) if isinstance(value, list) else sp.sympify(value, locals=names)
        state = {s: 0.3 + 0.1 * k for k, s in enumerate(names.values())}
        assert abs(complex(sp.N(sp.Matrix([back - mine]).subs(state).norm()))) < 1e-12
    assert "erratum" not in json.dumps(data).lower() or "lecture" in data


def test_the_notebook_shows_every_step_as_latex():
    shown = derived("rp_arm", None)._repr_latex_()
    assert shown.count(r"\begin{align*}") == 6 and "Erratum 1" in shown
    assert latex_math(derived("rp_arm", None)) == shown


def test_a_robot_with_more_than_four_moving_joints_is_refused_in_one_line():
    with pytest.raises(InputError) as error:
        derivation(str(DATA / "robots" / "mimic_tree.urdf"))
    assert error.value.argument == "source" and "derive_equations" in str(error.value) and "\n" not in str(error.value)


def test_the_cli_prints_the_derivation_and_refuses_code_formats(capsys):
    assert main(["equations", "rp_arm", "--derivation", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["robot"] == "rp_arm"
    assert main(["equations", "rp_arm", "--derivation", "--format", "c"]) == 2
    assert "format" in capsys.readouterr().err


def test_lecture_refuses_any_robot_but_the_rp_arm(capsys):
    assert main(["equations", str(DATA / "rrp_arm.urdf"), "--lecture"]) == 2
    err = capsys.readouterr().err
    assert "model" in err and "rrp_arm" in err and len(err.strip().splitlines()) == 1
    assert main(["equations", "rp_arm", "--lecture"]) == 0
    assert "errata" in capsys.readouterr().out


def overfull_boxes(log: str) -> list[float]:
    """The widths in [pt] of every overfull box pdflatex reports."""
    return [float(width) for width in re.findall(r"Overfull \\[hv]box \(([0-9.]+)pt too", log)]


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex")
@pytest.mark.parametrize("keep_params", [False, True], ids=["numbers", "kept"])
def test_the_rp_arms_latex_compiles_without_an_overfull_box(keep_params):
    tex = to_latex(derived("rp_arm", None, keep_params))
    with tempfile.TemporaryDirectory() as folder:
        pdf, log = compile_latex(tex, Path(folder))
        assert pdf.read_bytes().startswith(b"%PDF")
    assert "! " not in log
    assert max(overfull_boxes(log), default=0.0) <= 10.0
    # Negative control: the parser sees an overfull box when there is one.
    assert overfull_boxes("Overfull \\hbox (23.5pt too wide) in paragraph") == [23.5]


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex")
@pytest.mark.parametrize("case", CASES[1:], ids=[c[0] for c in CASES[1:]])
def test_every_robots_latex_compiles_without_an_overfull_box(case):
    _name, source, gravity = case
    with tempfile.TemporaryDirectory() as folder:
        _, log = compile_latex(to_latex(derived(source, gravity)), Path(folder))
    assert max(overfull_boxes(log), default=0.0) <= 10.0


def test_an_unknown_format_is_refused_before_any_derivation():
    with pytest.raises(InputError) as error:
        derivation_document("no such robot", format="python")  # type: ignore[arg-type]
    assert error.value.argument == "format"
