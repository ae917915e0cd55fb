"""The checks around a run on the ground: links that are no contact points going under it."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.contact_checks import buried_line
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground, contact_points

FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]


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
    <body name="body" pos="0 0 0.5">
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
        run_simulation(robot, controller="pd", ground=Ground(), duration=0.01)  # set down 5 cm under its head
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
