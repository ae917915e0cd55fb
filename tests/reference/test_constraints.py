"""The reference with multipliers (no Pinocchio): its ``Φ``, ``J``, ``J̇ v``, ``v̇``, ``λ`` against
the dynamics layer's through ``robodyn check``, negative controls of that check, the RP arm
on a wall against a free-body diagram, and a run where Pinocchio cannot be imported."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn import reference
from robodyn.constraints import FrameAnchor, PointAnchor, PointContact
from robodyn.reference import constraints as reference_constraints
from robodyn.urdf.models import RPArmParameters
from tests.constraints.linkages import DATA, GRAVITY, load_linkage

ROOT = Path(__file__).resolve().parent.parent.parent
CONSTRAINT_QUANTITIES = ("Phi", "J", "Jdot_v", "constrained_a", "lambda")


def assert_constraints_agree(robot: robodyn.Robot, samples: int = 12) -> None:
    report = robodyn.check_robot(robot, samples=samples, seed=3)
    assert set(CONSTRAINT_QUANTITIES) <= set(report.comparisons)
    assert report.passed, report.failures


@pytest.mark.parametrize("name", ["four_bar", "four_bar_3d", "parallelogram", "slider_crank"])
def test_the_linkages_agree_with_the_reference(name):
    assert_constraints_agree(load_linkage(name))


def test_welds_and_contacts_on_a_mimic_robot_agree_with_the_reference():
    constraints = [
        FrameAnchor("middle", (0.01, 0.02, 0.03, 0.1, 0.2, 0.3), "tip", None),
        PointAnchor("tip", (0.1, 0.02, 0.03), None, (0.3, 0.1, 0.2)),
        PointContact("upper", (0.05, 0.0, 0.0), normal=(0.3, -0.2, 1.0), friction=0.0, plane_point=(0, 0, 0.1)),
    ]
    robot = robodyn.load(ROOT / "tests" / "data" / "mimic_arm.urdf", gravity=GRAVITY, constraints=constraints)
    assert robot.mimic is not None
    assert_constraints_agree(robot)


def test_a_floating_base_with_a_closed_loop_and_sticking_feet_agrees_with_the_reference():
    robot = load_linkage("four_bar_3d", floating_base=True)
    robot = robodyn.load(
        DATA / "four_bar_3d.urdf",
        gravity=GRAVITY,
        floating_base=True,
        constraints=[*robot.constraints, PointContact("crank", (0.1, 0, 0), friction=0.5), FrameAnchor("rocker", frame2=None)],
    )
    assert_constraints_agree(robot)


def test_the_check_fails_when_the_reference_drops_the_drift_or_flips_the_constraint_force(monkeypatch):
    robot = load_linkage("slider_crank")
    rows = reference_constraints.state_rows

    def no_drift(*args):
        phi, jacobian, drift = rows(*args)
        return phi, jacobian, 0 * drift

    monkeypatch.setattr(reference_constraints, "state_rows", no_drift)
    failed = robodyn.check_robot(robot, samples=6, seed=3)
    assert {"Jdot_v", "constrained_a", "lambda"} <= {line.split(":")[0] for line in failed.failures}
    monkeypatch.setattr(reference_constraints, "state_rows", rows)
    solve = reference_constraints.solve_kkt
    # M a = f − Jᵀ λ with J a = −J̇ v: the same accelerations, the multipliers' sign flipped
    monkeypatch.setattr(reference_constraints, "solve_kkt", lambda m, f, j, d: solve(m, f, -j, -d))
    flipped = robodyn.check_robot(robot, samples=6, seed=3)
    assert {line.split(":")[0] for line in flipped.failures} == {"lambda"}


def rp_arm_on_wall(wall: float) -> PointContact:
    """The RP arm's tip sliding without friction on the wall x = ``wall`` (normal towards the arm)."""
    return PointContact("end_effector", normal=(-1.0, 0.0, 0.0), friction=0.0, plane_point=(wall, 0.0, 0.0), name="wall")


def test_the_rp_arm_at_rest_on_a_wall_gets_the_free_body_diagrams_force():
    p, g, wall, push = RPArmParameters(), 9.81, 0.8, 7.0
    robot = robodyn.load("rp_arm", constraints=[rp_arm_on_wall(wall)])
    q1 = 0.6
    reach = wall / math.cos(q1)  # shoulder to tip
    q = np.array([q1, reach - p.l1 - p.l2])
    assert np.allclose(robot.frame_position(q, "end_effector"), [wall, 0.0, reach * math.sin(q1)], atol=1e-14)
    # Free-body diagram: gravity on each link's centre, the wall's push (−push, 0, 0) on the tip.
    gravity = np.array([(p.m1 * g * p.l1 / 2 + p.m2 * g * (p.l1 + q[1] + p.l2 / 2)) * math.cos(q1), p.m2 * g * math.sin(q1)])
    wall_moment = np.array([push * reach * math.sin(q1), -push * math.cos(q1)])  # about the shoulder; along the slide
    tau = gravity - wall_moment
    a, lam = robot.constrained_forward_dynamics(q, np.zeros(2), tau)
    assert np.abs(a).max() < 1e-12 and abs(lam[0] - push) < 1e-12 * push
    model = reference.load("rp_arm")
    a_ref, lam_ref = reference_constraints.constrained_forward_dynamics(model, q, np.zeros(2), tau, [rp_arm_on_wall(wall)])
    assert np.abs(a_ref).max() < 1e-12 and abs(lam_ref[0] - push) < 1e-12 * push


def test_the_reference_with_multipliers_runs_where_pinocchio_cannot_be_imported():
    program = """
import sys
class Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('pinocchio', 'coal', 'hppfcl', 'cmeel'):
            raise ImportError('pinocchio is forbidden here: ' + name)
sys.meta_path.insert(0, Refuse())
from robodyn import reference
from robodyn.constraints import PointAnchor
from robodyn.reference.constraints import constrained_forward_dynamics
model = reference.load('tests/data/constraints/four_bar.urdf')
a, lam = constrained_forward_dynamics(model, [0.1, 0.2, 0.3], [0.0] * 3, [0.0] * 3, [PointAnchor('coupler', (0.35, 0, 0), 'rocker', (0.3, 0, 0))])
assert a.shape == (3,) and lam.shape == (3,)
assert not any(name.split('.')[0] == 'pinocchio' for name in sys.modules)
print('ok')
"""
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
