"""Issue 39, what a run on the ground may ask (``robodyn/sim/contact_checks.py``, through its
public functions): each refusal's whole sentence, the start's penetration bound on both
sides of 1 mm naming the deepest point, and a floating robot lifted along a tilted
ground's normal until its lowest contact point has the clearance asked; links that are no
contact points going under the ground."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_checks import START_PENETRATION, buried_line, check_contact_run, start_above
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground, contact_points

BOX = Path(__file__).resolve().parent.parent / "data" / "contact" / "box.urdf"  # 0.3 × 0.2 × 0.1 m
FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
FINE = {"integrator": "semi-implicit-euler", "every": None, "limits": "warn", "observer": None}


@pytest.fixture(scope="module")
def box() -> robodyn.Robot:
    return robodyn.load(BOX, floating_base=True)


def at_height(box: robodyn.Robot, z: float, pitch: float = 0.0) -> np.ndarray:
    """The box's centre at height ``z``, pitched about y (its +x end down for pitch > 0)."""
    return box.floating_configuration([0.0, 0.0, z], [0.0, pitch, 0.0])


@pytest.mark.parametrize(
    ("ground", "contacts", "changed", "message"),
    [
        (None, ["box"], {}, "contacts must be given only with a ground, got ['box']."),
        (None, "box", {}, "contacts must be given only with a ground, got 'box'."),
        (None, ["b" * 100], {}, f"contacts must be given only with a ground, got {repr(['b' * 100])[:80]}."),
        ("g" * 100, "collision", {}, f"ground must be a robodyn.sim.ground.Ground (a plane, its normal and friction), got {repr('g' * 100)[:80]}."),
        ("floor", "collision", {}, "ground must be a robodyn.sim.ground.Ground (a plane, its normal and friction), got 'floor'."),
        (Ground(), "collision", {"integrator": "rk4"}, "integrator must be 'semi-implicit-euler' with a ground (the contact step's scheme), got 'rk4'."),
        (
            Ground(),
            "collision",
            {"every": 2},
            "control_period must be the step dt with a ground (the contact step samples the controller each step), got 2 steps.",
        ),
        (Ground(), "collision", {"observer": object()}, "observer must be none with a ground (the contact step runs no observer), got an observer."),
    ],
)  # fmt: skip
def test_what_a_ground_run_does_not_do_is_refused_in_one_sentence(box, ground, contacts, changed, message):
    with pytest.raises(InputError) as error:
        check_contact_run(box, ground, contacts, q0=at_height(box, 0.1), **(FINE | changed))
    assert str(error.value) == message


def test_without_a_ground_there_are_no_contacts_and_a_control_period_of_one_step_is_the_step(box):
    assert check_contact_run(box, None, "collision", q0=at_height(box, 0.1), **FINE) is None
    found = check_contact_run(box, Ground(), "collision", q0=at_height(box, 0.1), **(FINE | {"every": 1}))
    assert found is not None and len(found.points) == 8


def test_a_start_deeper_than_a_millimetre_is_refused_naming_the_deepest_point(box):
    below = 0.05 - 0.9 * START_PENETRATION  # the bottom face 0.9 mm in the ground: accepted
    assert check_contact_run(box, Ground(), "collision", q0=at_height(box, below), **FINE) is not None
    # pitched: the +x bottom corners deepest, 1.2 mm in the ground
    pitch = 0.05
    depth = 0.15 * math.sin(pitch) + 0.05 * math.cos(pitch)
    q0 = at_height(box, depth - 1.2e-3, pitch)
    found = contact_points(box, "collision")
    gaps = contact_kinematics(box, q0, Ground(), found.points)[0]
    deepest = found.names[int(np.argmin(gaps))]
    with pytest.raises(InputError) as error:
        check_contact_run(box, Ground(), "collision", q0=q0, **FINE)
    assert str(error.value) == (
        "q0 must be a configuration with every contact point above the ground (at most 0.001 m below), "
        f"got {deepest!r} 0.0012 m below."
    )
    assert abs(gaps.min() + 1.2e-3) < 1e-12 and sorted(gaps)[2] > gaps.min() + 1e-3  # two corners that deep, not more


@pytest.mark.parametrize("clearance", [None, 0.0, 0.02])
def test_start_above_lifts_along_the_grounds_normal_to_the_clearance(box, clearance):
    ground = Ground.tilted(math.radians(20.0), friction=0.5, height=0.3)
    q0 = at_height(box, -0.2, 0.1)  # under the plane
    moved, lift = start_above(box, q0, ground, "collision", **({} if clearance is None else {"clearance": clearance}))
    clearance = 0.05 if clearance is None else clearance  # the default: 5 cm
    gaps_before = contact_kinematics(box, q0, ground, contact_points(box, "collision").points)[0]
    gaps = contact_kinematics(box, moved, ground, contact_points(box, "collision").points)[0]
    assert gaps.min() == pytest.approx(clearance, abs=1e-12)
    assert lift == pytest.approx(clearance - gaps_before.min(), abs=1e-12)
    np.testing.assert_allclose(moved[:3] - q0[:3], lift * np.array(ground.normal), atol=1e-15)
    np.testing.assert_array_equal(moved[3:], q0[3:])
    assert q0[2] == -0.2  # the caller's array untouched


def test_start_above_takes_a_configuration_of_integers():
    box = robodyn.load(BOX, floating_base=True)
    moved, lift = start_above(box, np.array([0, 0, 0, 0, 0, 0, 1]), Ground(), "collision")
    assert lift == pytest.approx(0.1) and moved[2] == pytest.approx(0.1)  # the bottom face 5 cm above z = 0


def test_a_link_that_is_no_contact_point_under_the_ground_is_named_with_its_depth():
    solo = robodyn.load("solo12")
    high, sunk = solo.neutral_configuration(), solo.neutral_configuration()
    high[2], sunk[2] = 0.6, -0.1  # the base's origin 0.1 m below the floor, the feet further down
    line = buried_line(solo, np.array([high, sunk]), np.array([0.0, 1.0]), Ground(), contact_points(solo, FEET))
    assert line is not None and line.startswith("warning: 13 links that are no contact points went under the ground")
    assert "(from t = 1 s; deepest): 'FL_LOWER_LEG' 0.26 m" in line  # the knees, 0.16 m below the base
    assert not any(foot in line for foot in FEET)  # contact points are the ground's business
    lower = Ground(height=-0.2)  # only the knees under it now
    line = buried_line(solo, np.array([sunk]), np.array([0.0]), lower, contact_points(solo, FEET))
    assert line is not None and line.startswith("warning: 4 links") and "'HR_LOWER_LEG' 0.06 m" in line


def test_a_run_that_stays_above_the_ground_has_no_buried_line():
    solo = robodyn.load("solo12")
    high = solo.neutral_configuration()
    high[2] = 0.6
    assert buried_line(solo, np.array([high]), np.array([0.0]), Ground(), contact_points(solo, FEET)) is None


# A floating body whose only collision sphere is on its head, 0.4 m above its (meshless) legs.
HEAD_ONLY = """<mujoco model="head_only">
  <worldbody>
    <body name="body" pos="0 0 0.1">
      <freejoint/>
      <geom type="box" size="0.2 0.1 0.02" mass="5" contype="0" conaffinity="0"/>
      <body name="leg" pos="0 0 -0.2">
        <joint name="knee" type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.02 0.02 0.2" mass="1" contype="0" conaffinity="0"/>
      </body>
      <geom name="head" type="sphere" pos="0.2 0 0.2" size="0.05" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_start_that_puts_links_under_the_ground_is_refused_naming_the_contacts(tmp_path):
    path = tmp_path / "head_only.xml"
    path.write_text(HEAD_ONLY)
    robot = robodyn.load(str(path))
    with pytest.raises(InputError, match=r"contacts must be contact points that hold the robot .* 'leg' 0\.\d+ m") as caught:
        run_simulation(
            robot, controller="pd", ground=Ground(), duration=0.01
        )  # the file puts the leg through the floor, the head above it
    assert "\n" not in str(caught.value)


# A planar hopper as Gymnasium writes it: root slides at the floor (pos -0.6) and a hinge, the
# massless frames between them ('torso__rootz' at z = rootz), a leg with a sphere for a foot.
PLANAR_HOPPER = """<mujoco model="planar_hopper">
  <worldbody>
    <body name="torso" pos="0 0 0.6">
      <joint name="rootx" type="slide" axis="1 0 0" pos="0 0 -0.6"/>
      <joint name="rootz" type="slide" axis="0 0 1" pos="0 0 -0.6"/>
      <joint name="rooty" type="hinge" axis="0 1 0"/>
      <geom type="box" size="0.1 0.05 0.05" mass="3" contype="0" conaffinity="0"/>
      <body name="leg" pos="0 0 -0.05">
        <joint name="hip" type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.02 0.02 0.25" pos="0 0 -0.25" mass="1" contype="0" conaffinity="0"/>
        <geom name="foot" type="sphere" pos="0 0 -0.5" size="0.03" mass="0.2"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="hip"/></actuator>
</mujoco>
"""


def test_a_planar_roots_massless_frames_below_the_ground_are_no_buried_links(tmp_path):
    path = tmp_path / "hopper.xml"
    path.write_text(PLANAR_HOPPER)
    hopper = robodyn.load(str(path))
    q0 = [0.0, -0.015, 0.0, 0.0]  # lowered: the foot 5 mm up, the rootz frame 15 mm under the ground
    trajectory, summary = run_simulation(hopper, controller="pd", ground=Ground(), q0=q0, duration=0.1)
    assert "under the ground" not in summary.text()
    assert trajectory.q[-1][1] < -0.0195  # it landed on its foot (it moved: the check saw the run)
