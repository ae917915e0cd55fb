"""Issue 39, the centroidal quantities' refusal of an overflow (mutmut's survivors in
``robodyn/dynamics/centroidal.py``): two 10¹¹ kg sliders, along x and y, one 10³⁰⁰ m out, have a finite state and
no finite centre of mass or momentum matrix; each is refused naming the quantity, never
returned as inf."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import NonFiniteResultError

HEAVY_SLIDER = """<robot name="heavy">
  <link name="base"/>
  <link name="slide">
    <inertial><mass value="1e11"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="across">
    <inertial><mass value="1e11"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="s" type="prismatic">
    <parent link="base"/><child link="slide"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="t" type="prismatic">
    <parent link="base"/><child link="across"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"""


def test_an_overflowing_centre_of_mass_or_momentum_matrix_is_refused_naming_it():
    robot = robodyn.load(HEAVY_SLIDER)
    far = np.array([1e300, 0.0])
    assert np.isfinite(robot.center_of_mass(np.array([0.5, -0.5]))).all()  # the control: a state in range
    with pytest.raises(NonFiniteResultError) as error:
        robot.center_of_mass(far)
    assert str(error.value) == "robot 'heavy': centre of mass overflowed to a non-finite value for finite inputs."
    with pytest.raises(NonFiniteResultError) as error:
        robot.centroidal_momentum_matrix(far)
    assert str(error.value) == "robot 'heavy': centroidal momentum matrix overflowed to a non-finite value for finite inputs."
