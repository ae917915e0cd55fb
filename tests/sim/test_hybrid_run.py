"""Issue 42, ``run_hybrid`` (what ``simulate --controller hybrid`` calls): the joints'
damping acts on the plant and the controller compensates it (the force and the motion laws
still hold; without the compensation they do not), the reference's derivatives are its
derivatives, a surface that pulls is said, and what a hybrid run does not take is refused."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim import hybrid_run
from robodyn.sim.hybrid_run import SlidingReference, run_hybrid, run_named
from robodyn.sim.surface_run import ForceOutcome, SurfaceRun
from robodyn.urdf.models.rp_arm import rp_arm_urdf

WALL = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0))


def _damped_arm():
    urdf = rp_arm_urdf().replace("</joint>", '<dynamics damping="3.0" friction="0.2"/></joint>', 2)
    return robodyn.load(urdf)


def _tangential_error(robot, trajectory, middle=0.0):
    tip = robot.frame_position(trajectory.q, "end_effector")
    return middle + 0.1 * np.sin(np.pi * trajectory.t) - tip[:, 2]


def test_the_damped_arm_presses_and_slides_by_the_law_its_controller_compensating_the_damping():
    robot = _damped_arm()
    assert robot.joint_damping.tolist() == [3.0, 3.0]
    trajectory, summary = run_hybrid(robot, force=10.0, surface=WALL, along=(0, 0, 0.1), duration=0.2, dt=0.02)
    assert summary.forces.peak_error <= 1e-6 * 10.0
    assert any("Coulomb friction" in line for line in summary.forces.lines())  # not modelled: said
    plain_trajectory, _ = run_hybrid(
        robodyn.load(rp_arm_urdf()), force=10.0, surface=WALL, along=(0, 0, 0.1), duration=0.2, dt=0.02
    )
    np.testing.assert_allclose(_tangential_error(robot, trajectory), _tangential_error(robot, plain_trajectory), atol=1e-9)


def test_without_the_compensation_the_damping_shows(monkeypatch):  # negative control
    robot = _damped_arm()
    monkeypatch.setattr(hybrid_run, "compensate", lambda law, joint_friction: None)  # the rigid-body law
    trajectory, _ = run_hybrid(robot, force=10.0, surface=WALL, along=(0, 0, 0.1), duration=0.2, dt=0.02)
    plain_trajectory, _ = run_hybrid(
        robodyn.load(rp_arm_urdf()), force=10.0, surface=WALL, along=(0, 0, 0.1), duration=0.2, dt=0.02
    )
    assert np.abs(_tangential_error(robot, trajectory) - _tangential_error(robot, plain_trajectory)).max() > 1e-4


def test_the_sliding_reference_is_a_circle_with_its_own_derivatives():
    reference = SlidingReference(np.array([0.3, 0.0, 0.5]), np.array([[0.05, 0, 0], [0, 0.05, 0]]), 0.5)
    times, h = np.linspace(0.0, 2.0, 9), 1e-5
    for t in times:
        x, dx, ddx = reference(t)
        assert abs(np.linalg.norm(x - [0.3, 0.0, 0.5]) - 0.05) <= 1e-15
        np.testing.assert_allclose(dx, (reference(t + h)[0] - reference(t - h)[0]) / (2 * h), atol=1e-9)
        np.testing.assert_allclose(ddx, (reference(t + h)[1] - reference(t - h)[1]) / (2 * h), atol=1e-8)


def test_a_surface_that_pulls_is_said():
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_hybrid(robot, force=1.0, surface=WALL, duration=0.02, dt=0.01)
    pulling = SurfaceRun(trajectory, "surface", "end_effector", np.array([-1.0, 0, 0]), np.array([1.0, -0.5, 1.0]), np.ones(3))
    lines = ForceOutcome.of(pulling, np.zeros((3, 3)), 0.0, ()).lines()
    assert any("the surface pulled (smallest normal force -0.5 N)" in line for line in lines)
    assert not any("pulled" in line for line in summary.forces.lines())  # negative control: it pushed


@pytest.mark.parametrize(
    ("options", "parameter"),
    [
        ({"engine": "compiled"}, "engine"),
        ({"integrator": "semi-implicit-euler"}, "integrator"),
        ({"control_period": 0.01}, "control_period"),
        ({"force_at": ["0.1:1,0,0"]}, "force_at"),
        ({"observer_gain": 10.0}, "observer_gain"),
        ({"limits": "enforce"}, "limits"),
        ({"gravity": 1.0}, "gravity"),
        ({"surface": (1.0, 0.0, 0.0)}, "surface"),
        ({"surface": None}, "surface"),
        ({"surface": ((1e300, 0.0, 0.0), (-1.0, 0.0, 0.0))}, "surface"),  # out of reach: the projection overflowed
        ({"force": None}, "force"),
    ],
)
def test_what_a_hybrid_run_does_not_take_is_refused_naming_it(options, parameter):
    robot = robodyn.load("rp_arm")
    settings = {"force": 1.0, "surface": WALL, "duration": 0.02, "dt": 0.01} | options
    with pytest.raises(InputError) as caught:
        run_named(robot, controller="hybrid", **settings)
    assert caught.value.argument == parameter


def test_hybrid_options_with_another_controller_are_refused():
    with pytest.raises(InputError) as caught:
        run_named(robodyn.load("rp_arm"), controller="passive", surface=WALL, duration=0.02)
    assert caught.value.argument == "surface"


def test_a_given_start_on_the_surface_is_the_runs_first_state_and_its_step_is_the_given_one():
    """The default start projected onto the wall, given back as ``q0``: the run starts there
    (not at the default configuration) and steps by the given ``dt``; the same start 1 cm off
    the wall is refused naming ``q0`` with its gap."""
    robot = robodyn.load("rp_arm")
    first, _ = run_hybrid(robot, force=1.0, surface=WALL, duration=0.02, dt=0.01)
    on_wall = first.q[0]
    assert np.abs(on_wall - robot.default_configuration()).max() > 1e-3  # the projection moved it
    trajectory, _ = run_hybrid(robot, force=1.0, surface=WALL, q0=on_wall, duration=0.04, dt=0.02)
    assert np.abs(trajectory.q[0] - on_wall).max() < 1e-12 and np.allclose(np.diff(trajectory.t), 0.02)
    off = on_wall.copy()
    off[1] += 0.01  # the prismatic joint: the tip leaves the wall
    gap = float(-(robot.frame_position(off, "end_effector")[0] - 1.0))
    with pytest.raises(InputError) as caught:
        run_hybrid(robot, force=1.0, surface=WALL, q0=off, duration=0.02, dt=0.01)
    assert caught.value.argument == "q0" and caught.value.received == f"{gap:.3g} m off it" and abs(gap) > 1e-4
