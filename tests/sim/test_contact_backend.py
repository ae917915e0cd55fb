"""A run on the ground through robodyn.simulate's plan: the Pinocchio backend's contact step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import Ground
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.plan import ExternalWrench
from robodyn.sim.simulation import simulate, simulate_run

DATA = Path(__file__).parents[1] / "data" / "contact"


@pytest.fixture(scope="module")
def box() -> robodyn.Robot:
    return robodyn.load(DATA / "box.urdf", floating_base=True)


def _dropped(box: robodyn.Robot) -> np.ndarray:
    q0 = box.neutral_configuration()
    q0[2] = 0.1
    return q0


def test_simulate_with_a_ground_is_the_contact_step_on_the_pinocchio_engine(box):
    ground = Ground(friction=0.5)
    trajectory, run = simulate_run(box, _dropped(box), np.zeros(6), 0.3, 1e-3, ground=ground)
    alone = simulate_contact(box, ground=ground, duration=0.3, q0=_dropped(box))
    assert run.engine == "pinocchio" and run.reason == "contact with a ground (the compiled engine models none)"
    assert np.array_equal(trajectory.q, alone.trajectory.q)
    assert np.array_equal(run.contact.forces, alone.forces)
    assert simulate(box, _dropped(box), np.zeros(6), 0.3, 1e-3).q[-1, 2] < -0.3  # without: it falls


def test_an_external_push_acts_on_a_box_on_the_ground(box):
    push = ExternalWrench("box", np.array([20.0, 0.0, 0.0]))  # above μ m g = 12.3 N: it slides
    trajectory, run = simulate_run(box, _dropped(box), np.zeros(6), 0.3, 1e-3, ground=Ground(friction=0.5), external=[push])
    assert trajectory.q[-1, 0] > 0.05
    assert run.contact.forces[-1, :, 0].sum() == pytest.approx(-0.5 * 2.5 * 9.81, rel=1e-9)  # kinetic friction


@pytest.mark.parametrize(
    ("options", "named"),
    [
        ({"engine": "compiled"}, "ground"),
        ({"integrator": "rk4"}, "integrator"),
        ({"ground": "floor"}, "ground"),
    ],
)
def test_what_a_contact_run_does_not_do_is_refused_by_name(box, options, named):
    with pytest.raises(InputError, match=named):
        simulate(box, _dropped(box), np.zeros(6), 0.1, 1e-3, **({"ground": Ground()} | options))


def test_contacts_without_a_ground_and_an_observer_on_the_ground_are_refused(box):
    with pytest.raises(InputError, match="contacts"):
        simulate(box, _dropped(box), np.zeros(6), 0.1, 1e-3, contacts=["box"])
    observer = MomentumObserver(box, 10.0, torque="sampled")
    with pytest.raises(InputError, match="observer"):
        simulate(box, _dropped(box), np.zeros(6), 0.1, 1e-3, ground=Ground(), observer=observer)
