"""The stand controller's feet (robodyn.sim.stand_run): only the contact points on the ground
at the start are feet. A collision sphere above it (a head, a hand) is no foot the QP may
push on: the law checked is that the feet carry m g (the robot's mass times gravity, not the
controller's numbers), in the QP and in the simulation, and the head carries nothing.
Before, every collision sphere was a foot and the QP pushed the robot up by its head.
An actuator without a limit (MJCF's motor without ctrlrange, a URDF's effort 0) is unlimited."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import ControllerFailedError, InputError
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground

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
