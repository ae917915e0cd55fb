"""simulate() holds a robot's constraints (closed loops, welds): the constrained loop, never the open tree."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.simulation import simulate_run
from tests.conftest import ROOT

FOUR_BAR = ROOT / "tests" / "data" / "constraints" / "four_bar.xml"


@pytest.fixture(scope="module")
def four_bar():
    return robodyn.load(FOUR_BAR)


def test_a_four_bar_from_mjcf_stays_closed_and_keeps_its_energy(four_bar):
    q0, v0 = four_bar.default_configuration(), np.zeros(four_bar.nv)
    trajectory, run = simulate_run(four_bar, q0, v0, 1.0, 1e-3)
    assert run.engine == "pinocchio" and "robot.constraints" in run.reason
    assert np.abs(four_bar.constraint_residual(trajectory.q)).max() < 1e-9
    energy = four_bar.kinetic_energy(trajectory.q, trajectory.v) + four_bar.potential_energy(trajectory.q)
    assert np.ptp(energy) < 1e-6 * max(1.0, np.ptp(four_bar.potential_energy(trajectory.q)))
    assert np.ptp(trajectory.q[:, 0]) > 0.1  # it moved: the check above is not of a robot at rest
    # negative control: the same tree without its loop (the URDF robodyn wrote) opens
    tree = robodyn.load(four_bar.urdf, gravity=four_bar.gravity_vector)
    assert tree.constraints == ()
    middle = len(trajectory.t) // 3  # a closed, moving state
    open_run, _ = simulate_run(tree, trajectory.q[middle], trajectory.v[middle], 1.0, 1e-3)
    assert np.abs(four_bar.constraint_residual(open_run.q)).max() > 1e-3


@pytest.mark.parametrize(
    ("options", "parameter"),
    [
        ({"integrator": "semi-implicit-euler"}, "integrator"),
        ({"limits": "enforce"}, "limits"),
        ({"engine": "compiled"}, "engine"),
    ],
)
def test_what_the_constrained_loop_does_not_model_is_refused_by_name(four_bar, options, parameter):
    with pytest.raises(InputError) as refused:
        simulate_run(four_bar, four_bar.default_configuration(), np.zeros(four_bar.nv), 0.01, 1e-3, **options)
    assert refused.value.argument == parameter
