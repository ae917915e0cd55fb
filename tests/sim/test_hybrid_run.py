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
from robodyn.urdf.models.pendulum import pendulum_urdf
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


def _three_link_start():
    """A planar 3R chain (links of 0.5 m) with its tip on the wall ``x = 0.6``: one joint
    more than the wall's two directions, so a one-dimensional null space ``n``."""
    robot = robodyn.load(pendulum_urdf(3, length=0.5))
    wall = ((0.6, 0.0, 0.0), (-1.0, 0.0, 0.0))
    first, _ = run_hybrid(robot, force=2.0, surface=wall, duration=0.01, dt=0.01)
    start = first.q[0]
    null = np.linalg.svd(robot.frame_jacobian(start, "tip")[:3])[2][-1]
    return robot, wall, start, null


def test_the_posture_pulls_the_arm_along_its_null_space_without_moving_the_task():
    """A posture 0.3 along the null space: after 0.8 s the arm is within a tenth of that of it
    (the law's gains 25 and 10: ``(1 + 5t) e^{-5t}`` ≈ 0.09), the tip held on its point and the
    force the command throughout. Negative control: without a posture it stays at its start."""
    robot, wall, start, null = _three_link_start()
    posture = start + 0.3 * null
    pulled, summary = run_hybrid(robot, force=2.0, surface=wall, q0=start, posture=posture, duration=0.8, dt=0.02)
    assert np.abs(pulled.q[-1] - posture).max() <= 0.1 * np.abs(posture - start).max()
    assert summary.forces.motion_peak <= 1e-6 and summary.forces.peak_error <= 1e-6 * 2.0  # RK4's steps: 1e-7, 3e-8
    assert np.abs(robot.frame_position(pulled.q, "tip") - robot.frame_position(start, "tip")).max() <= 1e-6
    held, _ = run_hybrid(robot, force=2.0, surface=wall, q0=start, duration=0.8, dt=0.02)
    assert np.abs(held.q - start).max() <= 1e-9


def test_the_summary_says_how_far_the_start_moved_onto_the_surface():
    """``start_moved`` is ``max |q₀ − default|`` of the written first state (the projection's
    move); a given start already on the surface moved by nothing."""
    robot, wall, start, _ = _three_link_start()
    _, summary = run_hybrid(robot, force=2.0, surface=wall, duration=0.01, dt=0.01)
    assert summary.forces.start_moved == np.abs(start - robot.default_configuration()).max() > 1.0
    assert "start: moved by 1.66 (max |dq|, rad / m)" in "\n".join(summary.forces.lines())  # |joint3| = 1.6596
    _, given = run_hybrid(robot, force=2.0, surface=wall, q0=start, duration=0.01, dt=0.01)
    assert given.forces.start_moved <= 1e-12


def test_the_summarys_motion_error_is_the_tips_distance_from_its_reference_in_the_surface():
    """The final and peak motion errors, recomputed from the written trajectory: the tip's
    distance (y, z: the wall's directions) from ``c + a sin(2π f t)`` with ``f`` the
    documented default 0.5 Hz, ``c`` the tip's start. Gains 4 and 1: an error to see."""
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_hybrid(robot, force=1.0, surface=WALL, along=(0, 0, 0.1), kp=4.0, kd=1.0, duration=0.3, dt=0.03)
    tip = robot.frame_position(trajectory.q, "end_effector")
    wanted = tip[0] + np.outer(np.sin(np.pi * trajectory.t), [0.0, 0.0, 0.1])
    errors = np.linalg.norm((wanted - tip)[:, 1:], axis=1)
    assert errors[-1] > 1e-3  # not degenerate
    np.testing.assert_allclose([summary.forces.motion_error, summary.forces.motion_peak], [errors[-1], errors.max()], rtol=1e-9)


def test_the_surface_drawn_is_a_grey_square_in_it_a_tenth_of_a_metre_beyond_the_motion():
    """The patch is a square in the surface about the motion's middle, its edges 0.1 m beyond
    the farthest point of the motion (sampled over a period): a line of amplitude 0.1 along
    z, a diagonal line (0.06, 0.08), a circle of radius 0.05, and a point held on an oblique
    plane (no part of its normal zero). It is the grey node ``surface`` of the recording."""
    robot = robodyn.load("rp_arm")
    middle, times = np.array([1.0, 0.0, 0.02]), np.linspace(0.0, 2.0, 81)
    oblique = ((0.9, 0.0, 0.0), (-0.8, 0.36, 0.48))  # through the tip's start, |n| = 1
    cases = [
        (WALL, (0, 0, 0.1), middle),
        (WALL, (0, 0.06, 0.08), middle),
        (WALL, ((0, 0.05, 0), (0, 0, 0.05)), middle),
        (oblique, None, np.array([0.9, 0.0, 0.0])),
    ]
    for surface, along, centre in cases:
        target = None if along is None else centre
        _, summary = run_hybrid(robot, force=1.0, surface=surface, along=along, target=target, duration=0.01, dt=0.01)
        (patch,) = summary.drawings
        corners, normal = patch.vertices, np.array(surface[1])
        assert patch.name == "surface" and len({(patch.colour >> shift) & 0xFF for shift in (0, 8, 16)}) == 1  # grey
        assert corners.shape == (4, 3) and np.abs((corners - surface[0]) @ normal).max() <= 1e-12  # in the surface
        np.testing.assert_allclose(corners.mean(axis=0), centre, atol=1e-12)
        edges = np.roll(corners, -1, axis=0) - corners
        sides = np.linalg.norm(edges, axis=1)
        assert np.ptp(sides) <= 1e-12 and abs(edges[0] @ edges[1]) <= 1e-12  # a square
        amplitudes = np.zeros((2, 3)) if along is None else np.vstack([np.reshape(along, (-1, 3)), np.zeros((1, 3))])[:2]
        path = np.outer(np.sin(np.pi * times), amplitudes[0]) + np.outer(np.cos(np.pi * times), amplitudes[1])
        reach = np.abs(path @ (edges[:2] / sides[:2, None]).T).max()
        assert abs(sides[0] / 2 - reach - 0.1) <= 1e-12


def test_another_frame_presses_and_holds_by_the_law_and_the_summary_names_it():
    """The 3R chain pressing with ``link3``'s origin (not its end effector): the force is the
    command and ``link3`` stays where it started (forward kinematics of the written ``q``);
    the summary's surface line names it, its step is the given one, its panel the forces."""
    robot = robodyn.load(pendulum_urdf(3, length=0.5))
    wall = ((0.6, 0.0, 0.0), (-1.0, 0.0, 0.0))
    trajectory, summary = run_hybrid(robot, force=2.0, surface=wall, frame="link3", duration=0.2, dt=0.02)
    held = robot.frame_position(trajectory.q, "link3")
    assert abs(held[0, 0] - 0.6) <= 1e-9 and np.abs(held - held[0]).max() <= 1e-6
    assert np.abs(summary.contact.measured - 2.0).max() <= 1e-6 * 2.0 and summary.forces.peak_error <= 1e-6 * 2.0
    assert summary.forces.surface == "surface: the origin of link3 slides on it without friction, normal [-1, 0, 0]"
    assert summary.dt == 0.02 and summary.forces.notes == ()  # no Coulomb friction in the file: nothing to say
    ((label, t, commanded, _), (measured_label, _, measured, _)) = summary.panels[0].curves
    assert (label, measured_label) == ("commanded force", "measured force") and np.array_equal(t, trajectory.t)
    assert np.all(commanded == 2.0) and np.array_equal(measured, summary.contact.measured)


def test_without_joint_friction_the_damped_arm_moves_as_the_undamped_one():
    """``joint_friction=False``: neither the plant's damping nor its note (the damped arm's
    motion is the plain arm's); with it the note is the one line said."""
    robot = _damped_arm()
    free, summary = run_hybrid(robot, force=10.0, surface=WALL, along=(0, 0, 0.1), joint_friction=False, duration=0.2, dt=0.02)
    plain, _ = run_hybrid(robodyn.load(rp_arm_urdf()), force=10.0, surface=WALL, along=(0, 0, 0.1), duration=0.2, dt=0.02)
    np.testing.assert_allclose(free.q, plain.q, atol=1e-12)
    assert summary.forces.notes == ()
    _, damped = run_hybrid(robot, force=10.0, surface=WALL, duration=0.02, dt=0.01)
    assert damped.forces.notes == ("joint Coulomb friction of the file is not applied in hybrid runs (the constrained plant)",)


def test_the_run_defaults_are_the_documented_three_seconds_in_steps_of_a_millisecond(monkeypatch):
    """``duration`` 3 s and ``dt`` 1 ms unless given (the simulation's call caught, not run)."""
    asked = {}

    def caught(robot, start, **options):
        asked.update(options)
        raise InterruptedError

    monkeypatch.setattr(hybrid_run, "simulate_constrained", caught)
    with pytest.raises(InterruptedError):
        run_hybrid(robodyn.load("rp_arm"), force=1.0, surface=WALL)
    assert asked["duration"] == 3.0 and asked["dt"] == 1e-3
