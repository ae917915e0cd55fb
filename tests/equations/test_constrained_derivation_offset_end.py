"""The derivation with multipliers on the smallest robot where a frame and a gravity can be
wrong: one hinge about y under gravity tilted off −z, whose link touches a frictionless floor
at a point offset in the link's own axes (the offset turns with the link). Its closed-form
``λ`` and ``q̈`` against robodyn's numeric constrained dynamics given the same gravity, at
random moving states; the control: the numbers of the default gravity differ."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.equations.constrained_derivation import derive_constrained

HINGE = """<robot name="hinge"><link name="base"/>
<joint name="hinge" type="revolute"><origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
<parent link="base"/><child link="arm"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
<link name="arm"><inertial><origin xyz="0.3 0 0.05" rpy="0 0 0"/><mass value="1.5"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.03"/></inertial></link></robot>"""
FLOOR = PointContact("arm", point=(0.6, 0.0, 0.1), normal=(0.0, 0.0, 1.0), friction=0.0, plane_point=(0.0, 0.0, -0.2))
GRAVITY = (2.0, 0.5, -9.0)


def test_the_derived_multiplier_is_the_numeric_one_with_the_offset_turning_and_gravity_tilted(tmp_path):
    path = tmp_path / "hinge.urdf"
    path.write_text(HINGE)
    derivation = derive_constrained(path, FLOOR, gravity=GRAVITY)
    robot = robodyn.load(path, constraints=[FLOOR], gravity=GRAVITY)
    default = robodyn.load(path, constraints=[FLOOR])
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, v, tau = rng.uniform(-1.0, 1.0, 1), rng.normal(size=1), rng.normal(size=1)
        a, lam = robot.constrained_forward_dynamics(q, v, tau)
        qdd, derived = derivation.solve(q, v, tau)
        assert derivation.multipliers(q, v, tau)[0] == pytest.approx(lam[0], rel=1e-9, abs=1e-9)
        np.testing.assert_allclose(np.concatenate([qdd, derived]), np.concatenate([a, lam]), rtol=1e-9, atol=1e-9)
        assert abs(default.constrained_forward_dynamics(q, v, tau)[1][0] - lam[0]) > 1e-3 * abs(lam[0])  # the control
