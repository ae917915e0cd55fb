"""Issue 42, ``run_simulation(controller="stand")``: solo12 on the ground held by the
whole-body QP. Laws: it starts on its feet (gap 0), its base stays where it started and the
feet carry ``m g`` (gravity's magnitude times the robot's mass, not the controller's numbers);
a commanded centre-of-mass shift of 2 cm is reached. Negative control: without the shift
(the hold run) the shift check fails."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground

LEGS = [0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6]
SHIFT = np.array([0.0, 0.02, 0.0])


@cache
def solo() -> robodyn.Robot:
    return robodyn.load("solo12")


@cache
def stand(shift: tuple[float, ...] | None, duration: float):
    """solo12 with bent legs (a stance that can shift its weight), started 0.1 m high."""
    robot = solo()
    q0 = list(robot.floating_configuration([0.0, 0.0, 0.4], [0.0, 0.0, 0.0], LEGS))
    return run_simulation(
        robot, controller="stand", ground=Ground(), q0=q0, duration=duration, target=None if shift is None else list(shift)
    )


def shift_missed(trajectory) -> float:
    robot = solo()
    moved = robot.center_of_mass(trajectory.q[-1]) - robot.center_of_mass(trajectory.q[0])
    return float(np.linalg.norm(moved - SHIFT))


def test_standing_it_starts_on_its_feet_holds_its_base_and_the_feet_carry_its_weight():
    robot = solo()
    trajectory, summary = stand(None, 1.0)
    contact = summary.contact
    assert np.abs(contact.gaps[0]).max() < 1e-12  # on the ground, not dropped from 5 cm
    assert summary.ground[0].startswith("start: the base moved")
    assert np.abs(trajectory.q[:, :3] - trajectory.q[0, :3]).max() < 1e-4
    weight = robot.total_mass * np.linalg.norm(robot.gravity_vector)
    assert abs(contact.normal_forces[-1].sum() - weight) <= 1e-6 * weight
    assert summary.com_error < 1e-6 and summary.force_difference < 1e-3 and summary.support_margin > 0.05
    text = summary.text()
    assert "centre of mass: final error" in text and "support margin" in text


def test_a_two_centimetre_shift_of_the_centre_of_mass_is_reached_and_without_it_the_check_fails():
    trajectory, summary = stand(tuple(SHIFT), 1.5)
    assert shift_missed(trajectory) < 1e-3
    assert summary.com_error < 1e-3
    held, _ = stand(None, 1.0)  # negative control: the shift not applied
    assert shift_missed(held) > 1e-2


def test_other_controllers_leave_the_summary_without_stand_lines():
    _, summary = run_simulation(solo(), ground=Ground(), duration=0.01)
    assert summary.com_error is None and "centre of mass" not in summary.text()
    assert "com_error_m" not in summary.to_dict()


@pytest.mark.parametrize(
    ("robot", "options", "argument"),
    [
        ("solo12", {"ground": Ground(), "target": [0.0, 0.5, 0.0]}, "target"),
        ("solo12", {"ground": Ground(), "target": [0.0, 0.5]}, "target"),
        ("solo12", {}, "ground"),
        ("solo12", {"ground": Ground(friction=0.0)}, "friction"),
        ("panda", {"ground": Ground()}, "controller"),
    ],
)
def test_a_stand_it_cannot_do_is_refused_naming_the_parameter(robot, options, argument):
    with pytest.raises(InputError) as error:
        run_simulation(robodyn.load(robot), controller="stand", duration=0.01, **options)
    assert error.value.argument == argument


@pytest.mark.parametrize("joint_friction", [True, False])
def test_the_stand_run_compensates_the_joints_damping_exactly_when_it_applies_it(joint_friction, monkeypatch):
    """The QP the run builds (caught on its way to the plant) adds ``b ∘ v`` to its
    equations of motion when the run's damping acts, as the other model-based laws do."""
    from robodyn.sim import experiment

    built = []
    monkeypatch.setattr(experiment, "simulate_run", lambda *args, **kwargs: built.append(kwargs["controller"]) or 1 / 0)
    robot = solo()
    q0 = list(robot.floating_configuration([0.0, 0.0, 0.4], [0.0, 0.0, 0.0], LEGS))
    with pytest.raises(ZeroDivisionError):
        run_simulation(robot, controller="stand", ground=Ground(), q0=q0, duration=0.01, joint_friction=joint_friction)
    assert built[0].compensate_damping is joint_friction and built[0].law.compensate_damping is joint_friction


def shifted_centre(robot: robodyn.Robot) -> np.ndarray:
    """The centre of mass over a 0.3 s stand run shifting it 2 cm, (N, 3) in [m]."""
    q0 = list(robot.floating_configuration([0.0, 0.0, 0.4], [0.0, 0.0, 0.0], LEGS))
    trajectory, _ = run_simulation(robot, controller="stand", ground=Ground(), q0=q0, duration=0.3, target=list(SHIFT))
    return np.atleast_2d(robot.center_of_mass(trajectory.q))


@pytest.mark.slow  # three 0.3 s contact runs, about 3 s
def test_on_damped_joints_the_stand_run_moves_as_on_rigid_ones_and_without_the_compensation_it_does_not(monkeypatch):
    """The contact step applies the joints' damping (solo12 with 0.02 to 0.06 N m s/rad
    written in): the centre of mass moves as the rigid robot's does; the negative control
    leaves the QP rigid (the run's ``compensate`` disabled)."""
    from robodyn.sim import experiment
    from tests.sim.test_whole_body_damping import damped_solo

    rigid = shifted_centre(solo())
    assert np.abs(shifted_centre(damped_solo()) - rigid).max() <= 1e-9  # [m]
    monkeypatch.setattr(experiment, "compensate", lambda law, joint_friction: None)
    assert np.abs(shifted_centre(damped_solo()) - rigid).max() > 1e-4
