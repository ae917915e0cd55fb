"""``--constraints FILE``: a user's URDF four-bar (examples/four_bar.urdf, its loop in
examples/four_bar_constraints.yaml) through info, check, simulate --record and
equations --derivation; a hostile file is one stderr line, exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.cli.app import main
from robodyn.constraints.files import read_constraints
from robodyn.trajectory.columns import constraint_columns
from robodyn.trajectory.io import read_table

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
URDF, LOOP = str(EXAMPLES / "four_bar.urdf"), str(EXAMPLES / "four_bar_constraints.yaml")


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("anchor:\n  - frame1: nowhere\n", "constraints[0].frame1 must be a link of robot 'four_bar' ('world', 'ground'"),
        ("anchor:\n  - frame1: crank\n    point1: [.nan, 0, 0]\n", "anchor[0].point1[0] must be a finite number"),
        ("anchor:\n  - frame1: crank\n    point1: [1.0e300, 0, 0]\n", "within ±1e+06"),
        ("anchor: [\n", "--constraints must be a YAML file"),
    ],
)
def test_a_hostile_constraints_file_is_one_stderr_line_and_exit_2(capsys, tmp_path, text, said):
    path = tmp_path / "loop.yaml"
    path.write_text(text)
    status, out, err = run(capsys, "info", URDF, "--constraints", str(path))
    assert (status, out) == (2, "")
    assert len(err.strip().splitlines()) == 1 and said in err


def test_constraints_on_equations_outputs_that_are_the_open_trees_are_refused(capsys):
    status, out, err = run(capsys, "equations", URDF, "--constraints", LOOP, "--q", "0.1,0.2,0.3")
    assert (status, out) == (2, "") and "--constraints must be given only with --derivation or --symbolic" in err


def kkt_from_json(document: dict, q: np.ndarray, v: np.ndarray, tau: np.ndarray, *, sign: float = 1.0, drift: bool = True):
    """q̈ and λ (kept rows) of the printed derivation's matrices at a state: M, C q̇, G of
    steps 1–6, J and J̇ q̇ of steps 7–8 read back with sympy (``sign``: of Jᵀλ, ``drift``:
    whether J̇ q̇ is kept — the negative controls)."""
    symbols = {name: sp.Symbol(name, real=True) for name in (*document["q"], *document["qd"])}
    values = {symbols[name]: x for name, x in zip((*document["q"], *document["qd"]), (*q, *v), strict=True)}

    def numbers(rows) -> np.ndarray:  # a column is a list of strings, a matrix a list of rows
        rows = [[row] if isinstance(row, str) else row for row in rows]
        return np.array([[float(sp.sympify(e, locals=symbols).xreplace(values)) for e in row] for row in rows])

    constrained = document["constrained"]
    mass, jacobian = numbers(document["M"]), numbers(constrained["J"])
    force = tau - numbers(document["Cv"]).ravel() - numbers(document["G"]).ravel()
    rows = len(jacobian)
    kkt = np.block([[mass, -sign * jacobian.T], [jacobian, np.zeros((rows, rows))]])
    rhs = np.concatenate([force, -numbers(constrained["Jdot_qd"]).ravel() * drift])
    solution = np.linalg.lstsq(kkt, rhs, rcond=1e-11)[0]
    return solution[: len(q)], solution[len(q) :]


@pytest.mark.slow
def test_a_users_urdf_four_bar_goes_through_info_check_simulate_and_the_derivation(capsys, tmp_path, rng):
    status, out, _ = run(capsys, "info", URDF, "--constraints", LOOP)
    assert status == 0 and "point anchor 'loop' (3 rows)" in out and "1 redundant" in out
    status, out, _ = run(capsys, "check", URDF, "--constraints", LOOP, "--samples", "3")
    assert status == 0 and "constraint multipliers lambda (KKT)" in out and out.strip().endswith("PASSED")
    csv, html = tmp_path / "four_bar.csv", tmp_path / "four_bar.html"
    argv = ["simulate", URDF, "--constraints", LOOP, "--duration", "0.2", "--out", str(csv), "--record", str(html)]
    status, out, _ = run(capsys, *argv, "--json")
    summary = json.loads(out)
    assert status == 0 and html.stat().st_size > 1000
    assert summary["constraint_residual_max_m"] <= 1e-9 and summary["constraint_peak_force_N"]["loop"] > 0.1
    robot = robodyn.load(URDF, constraints=read_constraints(LOOP))
    table, layout, _ = read_table(csv)
    lam = constraint_columns(list(layout.header), table, [("loop", axis, "N") for axis in "xyz"])
    column = [list(layout.header).index(f"{kind}[{j}]") for kind in ("q", "v") for j in robot.joint_names]
    q, v = table[:, column[:3]], table[:, column[3:]]
    assert np.abs(robot.constraint_residual(q)).max() <= 1e-9  # the loop held at every recorded state
    assert summary["constraint_peak_force_N"]["loop"] == pytest.approx(np.linalg.norm(lam, axis=1).max(), rel=1e-12)

    status, out, _ = run(capsys, "equations", URDF, "--constraints", LOOP, "--derivation", "--format", "json")
    document = json.loads(out)
    assert status == 0 and document["constrained"]["rows"] == ["loop.x", "loop.z"]  # the y row is 0 = 0 (planar x-z)
    assert document["constrained"]["dropped_rows"] == ["loop.y"]
    order = [robot.joint_names.index(name) for name in document["joint_names"]]
    for _ in range(3):
        q, v, tau = robot.random_configuration(rng), rng.normal(size=3), rng.normal(size=3)
        a, lam = robot.constrained_forward_dynamics(q, v, tau)
        qdd, lam_derived = kkt_from_json(document, q[order], v[order], tau[order])
        assert np.abs(qdd - a[order]).max() <= 1e-9 * max(1.0, np.abs(a).max())
        assert np.abs(lam_derived - lam[[0, 2]]).max() <= 1e-9 * max(1.0, np.abs(lam).max())
        wrong = kkt_from_json(document, q[order], v[order], tau[order], sign=-1.0)[1]
        assert np.abs(wrong - lam[[0, 2]]).max() > 1e-3  # a wrong sign of Jᵀλ is caught
        missing = kkt_from_json(document, q[order], v[order], tau[order], drift=False)[0]
        assert np.abs(missing - a[order]).max() > 1e-3  # and a missing J̇ q̇
