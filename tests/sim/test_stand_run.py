"""The stand controller's feet (robodyn.sim.stand_run): only the contact points on the ground
at the start are feet. A collision sphere above it (a head, a hand) is no foot the QP may
push on: the law checked is that the feet carry m g (the robot's mass times gravity, not the
controller's numbers), in the QP and in the simulation, and the head carries nothing.
Before, every collision sphere was a foot and the QP pushed the robot up by its head.
An actuator without a limit (MJCF's motor without ctrlrange, a URDF's effort 0) is unlimited."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import ControllerFailedError, InputError
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground, contact_points
from robodyn.sim.stand_run import RecordedStand, stand_law

# A floating table on four sphere feet with a nodding head (a sphere 0.3 m above the ground).
TABLE = """<mujoco model="table_with_head">
  <worldbody>
    <geom type="plane" size="5 5 .1"/>
    <body name="body" pos="0 0 0.3">
      <freejoint/>
      <geom type="box" size="0.2 0.1 0.02" mass="5" contype="0" conaffinity="0"/>
      <geom type="sphere" pos="0.2 0.1 -0.2" size="0.02" mass="0.1"/>
      <geom type="sphere" pos="0.2 -0.1 -0.2" size="0.02" mass="0.1"/>
      <geom type="sphere" pos="-0.2 0.1 -0.2" size="0.02" mass="0.1"/>
      <geom type="sphere" pos="-0.2 -0.1 -0.2" size="0.02" mass="0.1"/>
      <body name="neck" pos="0.2 0 0.05">
        <joint name="nod" type="hinge" axis="0 1 0"/>
        <geom name="head" type="sphere" pos="0.05 0 0.05" size="0.05" mass="1"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="nod"/></actuator>
</mujoco>
"""


def test_a_collision_sphere_above_the_ground_is_no_foot_and_the_feet_carry_the_weight(tmp_path):
    path = tmp_path / "table.xml"
    path.write_text(TABLE)
    table = robodyn.load(str(path))
    _, summary = run_simulation(table, controller="stand", ground=Ground(), duration=0.05)
    assert "feet: the 4 of 5 contact points within 0.001 m of the ground at the start" in summary.text()
    forces = summary.contact.forces  # (N, 5, 3): the simulated ones, the head last
    assert np.allclose(forces[-1, :4, 2].sum(), table.total_mass * 9.81, rtol=1e-6)
    commanded = summary.contact.commanded  # the QP's (N, 5, 3); the feet share the weight as it likes (one rigid body)
    assert np.allclose(commanded[-1, :, 2].sum(), table.total_mass * 9.81, rtol=1e-6)
    assert np.abs(commanded[:, 4]).max() == 0.0 and np.abs(forces[:, 4]).max() == 0.0  # the head: none


def test_feet_that_do_not_hold_the_start_are_refused_naming_the_contacts_not_a_target(tmp_path):
    path = tmp_path / "table.xml"
    path.write_text(TABLE.replace('pos="-0.2 ', 'pos="0.25 '))  # every foot ahead of the centre of mass
    with pytest.raises(InputError, match=r"contacts must be feet whose support polygon holds .* on 'body'") as caught:
        run_simulation(robodyn.load(str(path)), controller="stand", ground=Ground(), duration=0.01)
    assert caught.value.argument == "contacts"  # no target was given: the refusal names the feet


def test_a_qp_without_solution_stops_the_run_saying_when(tmp_path):
    path = tmp_path / "table.xml"
    path.write_text(TABLE)
    table = robodyn.load(str(path))
    q0 = list(table.floating_configuration([0.0, 0.0, 0.5], [0.0, 0.5, 0.0], [0.0]))  # its feet on the slope
    slope = Ground.tilted(0.5, friction=0.1)  # μ = 0.1 < tan 0.5: no force in the cones holds it
    with pytest.raises(ControllerFailedError, match=r"stopped at t = 0 s \(step 0\): the controller failed \(the whole-body QP"):
        run_simulation(table, controller="stand", ground=slope, q0=q0, duration=0.01)


class _Law:
    """A stand law's stand-in: two feet, forces of its own, failing on a negative time."""

    contacts = ("front", "back")
    model = SimpleNamespace(dofs=[SimpleNamespace(joint=name) for name in ("base_x", "hip", "knee")])
    compensate_damping = False

    def __init__(self) -> None:
        self.seen: list[float] = []
        self.last_forces = np.zeros(6)

    def __call__(self, t, q, v):
        if t < 0:
            raise InputError("q", "a state from which the contacts can carry the robot", "a QP PrimalInfeasible")
        self.seen.append(t)
        self.last_forces = np.arange(6.0) + t
        return -v


def test_the_recorded_stand_files_each_calls_forces_under_its_feet_and_holds_the_last_one_in_force():
    """Feet 0 and 2 of three contact points: each call's QP forces land on them (the middle
    point carries none); ``held`` gives the forces of the last call at or before each time
    (before the first call: the first; between calls: the earlier; after: the last)."""
    law = _Law()
    recorded = RecordedStand(law, feet=[0, 2], count=3)
    for t in (0.0, 0.01, 0.02):
        assert np.array_equal(recorded(t, np.zeros(3), np.array([0.1, -0.2, 0.0])), [-0.1, 0.2, 0.0])
    assert law.seen == [0.0, 0.01, 0.02] and recorded.times == [0.0, 0.01, 0.02]
    assert np.array_equal(recorded.forces[1].reshape(3, 3), [[0.01, 1.01, 2.01], [0, 0, 0], [3.01, 4.01, 5.01]])
    held = recorded.held(np.array([-0.005, 0.0, 0.005, 0.01, 0.015, 0.02, 0.5]))
    assert held.shape == (7, 3, 3)
    assert np.array_equal(held[:, 0, 0], [0.0, 0.0, 0.0, 0.01, 0.01, 0.02, 0.02])
    every = RecordedStand(_Law())  # every contact a foot
    every(0.0, np.zeros(3), np.zeros(3))
    assert every.feet == [0, 1] and every.count == 2 and np.array_equal(every.forces[0], np.arange(6.0))


def test_a_qp_failing_mid_run_names_the_time_the_step_and_the_fastest_joint():
    recorded = RecordedStand(_Law())
    recorded(0.0, np.zeros(3), np.zeros(3))
    with pytest.raises(ControllerFailedError) as caught:
        recorded(-1.0, np.zeros(3), np.array([0.1, -0.7, 0.3]))
    error = caught.value
    assert (error.time, error.step, error.joint, error.speed) == (-1.0, 1, "hip", -0.7)
    assert error.reason == "the whole-body QP: a QP PrimalInfeasible, a state from which the contacts can carry the robot"


def test_each_stand_it_cannot_do_is_refused_in_one_sentence_naming_the_parameter(tmp_path):
    path = tmp_path / "table.xml"
    path.write_text(TABLE)
    table, arm = robodyn.load(str(path)), robodyn.load("rp_arm")
    start = table.neutral_configuration()
    cases = [
        ((arm, arm, arm.neutral_configuration(), None, Ground(), "collision"), "controller",
         "controller must be another controller than 'stand' for a fixed-base robot (stand holds a floating one on its feet), got 'rp_arm'."),
        ((table, table, start, None, None, "collision"), "ground",
         "ground must be given for the stand controller (the robot stands on it), got no ground."),
        ((table, table, start, None, Ground(friction=0.0), "collision"), "friction",
         "friction must be a coefficient > 0 for the stand controller (its feet stick), got 0.0."),
        ((table, table, start, [0.0, 0.01], Ground(), "collision"), "target",
         "target must be DX,DY,DZ in [m] (the centre of mass's shift) for the stand controller, got 2 values."),
        ((table, table, start, [0.0, 0.0, float("nan")], Ground(), "collision"), "target",
         "target must be DX,DY,DZ in [m] (the centre of mass's shift) for the stand controller, got 3 values."),
    ]  # fmt: skip
    for arguments, parameter, sentence in cases:
        with pytest.raises(InputError) as caught:
            stand_law(*arguments)
        assert caught.value.argument == parameter and str(caught.value) == sentence
    law, placed, line = stand_law(table, table, start, [0.01, 0.0, 0.0], Ground(), "collision")  # the negative control
    assert len(law.law.contacts) == 4 and law.count == 5 and law.feet == [0, 1, 2, 3]
    assert np.abs(law.law.com - table.center_of_mass(placed) - [0.01, 0.0, 0.0]).max() < 1e-15
    assert line.startswith("start: the base moved ")
    assert line.endswith("; feet: the 4 of 5 contact points within 0.001 m of the ground at the start")
    points = contact_points(table, "collision").points
    for foot, point in zip(law.law.contacts, points[:4], strict=True):  # each sphere's lowest point, its name
        assert foot.name == point.name and abs(foot.point[2] - (point.position[2] - point.radius)) < 1e-15
    with pytest.raises(InputError) as caught:
        stand_law(table, table, start, [1.0, 0.0, 0.0], Ground(), "collision")
    assert (
        caught.value.argument == "target"
        and caught.value.received == f"{table.center_of_mass(placed)[0] + 1.0 - 0.2:.3g} m outside it"
    )
    assert caught.value.expected == "a centre of mass shift that stays over the support polygon of the feet"


def _rotation(axis: int, angle: float) -> np.ndarray:
    """The rotation by ``angle`` [rad] about world axis ``axis`` (0, 1, 2), written out."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    rotation = np.eye(3)
    rotation[i, i], rotation[i, j], rotation[j, i], rotation[j, j] = c, -s, s, c
    return rotation if axis != 1 else rotation.T  # about y: z → x is the positive turn


def test_a_turned_start_on_a_slope_is_the_attitude_the_stand_holds(tmp_path):
    """The table pitched 0.5 rad onto a slope of 0.5 rad and turned 0.8 rad about its own
    normal (every part of its quaternion non-zero, its four feet on the slope): the attitude
    the law holds is that rotation, ``R_y(0.5) R_z(0.8)``, written out here."""
    path = tmp_path / "table.xml"
    path.write_text(TABLE)
    table = robodyn.load(str(path))
    rotation = _rotation(1, 0.5) @ _rotation(2, 0.8)
    w = np.sqrt(1 + np.trace(rotation)) / 2
    xyz = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]]) / (4 * w)
    assert np.abs(xyz).min() > 0.05  # no part zero: a swap of parts shows
    start = np.concatenate([[0.0, 0.0, 0.5], xyz, [w], [0.0]])  # Pinocchio's (x, y, z, w)
    law, _, _ = stand_law(table, table, start, None, Ground.tilted(0.5), "collision")
    assert law.feet == [0, 1, 2, 3]
    np.testing.assert_allclose(law.law.orientation, rotation, atol=1e-12)


# The table without its head, and with a sphere on its back listed before the feet.
HEADLESS = TABLE[: TABLE.index('      <body name="neck"')] + "    </body>\n  </worldbody>\n</mujoco>\n"
BACK_FIRST = TABLE.replace(
    '<geom type="sphere" pos="0.2 0.1 -0.2"',
    '<geom type="sphere" pos="0 0 0.1" size="0.03" mass="0.1"/>\n      <geom type="sphere" pos="0.2 0.1 -0.2"',
    1,
)


def test_when_every_contact_point_is_a_foot_the_start_line_says_no_feet(tmp_path):
    path = tmp_path / "table.xml"
    path.write_text(HEADLESS)
    table = robodyn.load(str(path))
    law, _, line = stand_law(table, table, table.neutral_configuration(), None, Ground(), "collision")
    assert law.feet == [0, 1, 2, 3] and law.count == 4
    lift = 0.2 + 0.02  # neutral: the base at the origin, the feet's centres 0.2 m below it, their radius 0.02 m
    assert line == (
        f"start: the base moved {lift:.6g} m along the ground's normal (its lowest contact point on it: stand's feet do not move)"
    )  # no "; feet: the 4 of 4 ..."


def test_a_point_above_the_ground_listed_before_the_feet_carries_no_force(tmp_path):
    """The back's sphere is contact point 0: the QP's forces of the four feet are filed under
    points 1 to 4 (they carry m g together), point 0 under none."""
    path = tmp_path / "table.xml"
    path.write_text(BACK_FIRST)
    table = robodyn.load(str(path))
    law, placed, line = stand_law(table, table, table.neutral_configuration(), None, Ground(), "collision")
    assert law.feet == [1, 2, 3, 4] and law.count == 6 and "the 4 of 6 contact points" in line
    law(0.0, placed, np.zeros(table.nv))
    forces = law.forces[0].reshape(6, 3)
    assert np.abs(forces[[0, 5]]).max() == 0.0
    assert abs(forces[1:5, 2].sum() - table.total_mass * 9.81) <= 1e-6 * table.total_mass * 9.81


def test_feet_that_cannot_stand_are_refused_in_one_sentence_with_how_far_or_how_many(tmp_path):
    """Every foot ahead of the centre of mass: the sentence says by how far, recomputed here
    from the masses (the box 5 kg at x = 0, spheres 0.1 kg at 0.2 and 0.25, the head 1 kg at
    0.25); two feet only: no polygon, the sentence counts them."""
    ahead, two = tmp_path / "ahead.xml", tmp_path / "two.xml"
    ahead.write_text(TABLE.replace('pos="-0.2 ', 'pos="0.25 '))
    two.write_text(TABLE.replace('<geom type="sphere" pos="-0.2 0.1 -0.2" size="0.02" mass="0.1"/>', "", 1).replace(
        '<geom type="sphere" pos="-0.2 -0.1 -0.2" size="0.02" mass="0.1"/>', "", 1))  # fmt: skip
    com_x = (0.1 * (0.2 + 0.2 + 0.25 + 0.25) + 1.0 * 0.25) / (5 + 0.4 + 1)
    cases = [
        (ahead, f"contacts must be feet whose support polygon holds the centre of mass at the start (name them), "
         f"got {0.2 - com_x:.3g} m outside the polygon of 4 points on 'body'."),
        (two, "contacts must be feet spanning a support polygon (three points or more off one line), got 2 points."),
    ]  # fmt: skip
    for path, sentence in cases:
        table = robodyn.load(str(path))
        with pytest.raises(InputError) as caught:
            stand_law(table, table, table.neutral_configuration(), None, Ground(), "collision")
        assert str(caught.value) == sentence
