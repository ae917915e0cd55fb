"""The step-by-step derivation on a 3-D robot in the fast tier (the planar RP arm alone
cannot tell ``R I Rᵀ`` from ``Rᵀ I R``: its links turn about one axis).

``yaw_pitch``: a revolute about z carrying a revolute about x, the second link with three
distinct principal moments and a centre of mass off both axes, under a sideways gravity.
``mimic_pair``: a yaw carrying a roll that mimics it (multiplier −1.5, offset 0.2 rad): one
degree of freedom, two bodies turning about crossed axes.
The checks are the derivation tests' own (per-link energies against Pinocchio's, the matrix
form against Pinocchio's M, C, G, each with its negative control), run on this robot.
"""

from __future__ import annotations

import pytest

from tests.equations import test_derivation as checks

YAW_PITCH = """<robot name="yaw_pitch"><link name="base"/>
<joint name="yaw" type="revolute"><parent link="base"/><child link="column"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
  <limit lower="-3" upper="3" effort="60" velocity="2"/></joint>
<link name="column"><inertial><origin xyz="0.02 0 0.1"/><mass value="1.5"/>
  <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.025" iyz="0" izz="0.01"/></inertial></link>
<joint name="pitch" type="revolute"><parent link="column"/><child link="arm"/><origin xyz="0 0 0.25"/><axis xyz="1 0 0"/>
  <limit lower="-2" upper="2" effort="40" velocity="2"/></joint>
<link name="arm"><inertial><origin xyz="0 0.1 0.15"/><mass value="0.8"/>
  <inertia ixx="0.008" ixy="0" ixz="0" iyy="0.012" iyz="0" izz="0.018"/></inertial></link>
</robot>"""
MIMIC_PAIR = """<robot name="mimic_pair"><link name="base"/>
<joint name="swing" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
  <limit lower="-3" upper="3" effort="60" velocity="2"/></joint>
<link name="upper"><inertial><origin xyz="0.2 0.02 0"/><mass value="1.2"/>
  <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.021"/></inertial></link>
<joint name="follow" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
  <limit lower="-3" upper="3" effort="60" velocity="2"/><mimic joint="swing" multiplier="-1.5" offset="0.2"/></joint>
<link name="lower"><inertial><origin xyz="0.1 0.05 -0.08"/><mass value="0.7"/>
  <inertia ixx="0.006" ixy="0" ixz="0" iyy="0.009" iyz="0" izz="0.012"/></inertial></link>
</robot>"""
CASES = [("yaw_pitch", YAW_PITCH, (0.5, -1.0, -9.5)), ("mimic_pair", MIMIC_PAIR, None)]


CHECKS = {
    "energy": checks.test_each_link_energy_sums_to_the_robots_energy,
    "centre_of_mass": checks.test_each_links_centre_of_mass_is_pinocchios,
    "tau": checks.test_each_joints_tau_is_the_inverse_dynamics,
    "matrix_form": checks.test_the_matrix_form_is_pinocchios_M_C_and_G,
}
#: The mimic pair has one degree of freedom: C and Cᵀ are one number there (the matrix
#: form's negative control cannot fail); its tau check covers M, C and G.
RUNS = [(check, case) for case in CASES for check in CHECKS if not (case[0] == "mimic_pair" and check == "matrix_form")]


@pytest.mark.parametrize(("check", "case"), RUNS, ids=[f"{case[0]}-{check}" for check, case in RUNS])
def test_the_derivation_of_a_3d_robot_is_pinocchios(check, case):
    CHECKS[check](case)
