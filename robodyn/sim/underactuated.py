"""PD and computed torque on a robot some of whose joints no actuator drives.

A file that lists its actuators (MJCF ``<actuator>``) says which joints are driven
(:attr:`robodyn.dynamics.dofs.Dof.actuated`): a planar walker's root joints (``rootx``,
``rootz``, ``rooty``) carry the whole body and have no motor. These laws give such joints
**zero torque**, as a floating base's six get none:

- :class:`UnderactuatedPD`: ``tau_a = Kp (q_d − q)_a − Kd v_a + g_a``, ``tau_u = 0``, where
  ``g_a`` holds the driven joints still with the others free (at rest, ``a_a = 0`` and
  ``a_u = −M_uu⁻¹ G_u``: ``g = M a + G``), not the rows of ``G(q)``, which hold a robot whose
  every joint is held;
- :class:`UnderactuatedComputedTorque`: the driven joints get the accelerations of the
  computed-torque law, the others the accelerations that motion causes
  (``a_u = −M_uu⁻¹ (M_ua a_a + h_u)``), ``tau = M a + h`` with ``tau_u = 0`` exactly.

Neither has a compiled twin: the compiled engine calls them from Python at every stage
(the plant still in C), so both engines give the same run.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.sim.control import ComputedTorque, PDGravity
from robodyn.sim.linearize import actuation_matrix


def driven_torques(model: Robot, q: np.ndarray, v: np.ndarray, accelerations: np.ndarray, driven: np.ndarray) -> np.ndarray:
    """Torques giving the driven degrees of freedom (``driven``, a mask of shape (nv,))
    the ``accelerations`` (shape (number driven,)) with zero torque on the others, whose
    accelerations are those the motion causes; shape (nv,), zero where not driven.

    The undriven rows of ``M a + h = tau`` with ``tau_u = 0`` give
    ``a_u = −M_uu⁻¹ (M_ud a_d + h_u)``.

    Args:
        model: The controller's model of the robot.
        q: Configuration, shape (nq,), in [rad] / [m].
        v: Velocity, shape (nv,), in [rad/s] / [m/s].
        accelerations: The driven degrees of freedom's accelerations in [rad/s²] / [m/s²], shape (number driven,).
        driven: Mask of the driven degrees of freedom, shape (nv,) (:func:`driven_dofs`).
    """
    mass, effects = model.mass_matrix(q), model.nonlinear_effects(q, v)
    free = ~driven
    acceleration = np.zeros(len(v))
    acceleration[driven] = accelerations
    acceleration[free] = -np.linalg.solve(mass[np.ix_(free, free)], mass[np.ix_(free, driven)] @ accelerations + effects[free])
    torques = mass @ acceleration + effects
    torques[free] = 0.0
    return torques


def driven_dofs(robot: Robot, actuated: list[str] | None) -> np.ndarray:
    """Which degrees of freedom an actuator drives, shape (nv,): those of the ``actuated``
    joints, or by default those whose :attr:`~robodyn.dynamics.dofs.Dof.actuated` (never a
    floating base's six).

    Args:
        robot: The robot.
        actuated: Names of the actuated joints; ``None``: those whose ``Dof.actuated`` is true.

    Raises:
        InputError: ``actuated`` naming an unknown joint, one twice, or none.
    """
    if actuated is None:
        return np.array([dof.actuated and not dof.is_base for dof in robot.dofs])
    actuation_matrix(robot, actuated)  # checks the names
    return np.array([dof.joint in actuated and not dof.is_base for dof in robot.dofs])


def _joint_rows(model: Robot) -> slice:
    """The joints' rows of ``v`` (a floating base's six left out)."""
    return slice(6, None) if model.floating_base else slice(0, None)


@dataclass
class UnderactuatedPD(PDGravity):
    """:class:`~robodyn.sim.control.PDGravity` with zero torque on the joints not driven.

    Attributes:
        driven: Which degrees of freedom an actuator drives, shape (nv,) (a floating
            base's six: false). The other attributes: as for ``PDGravity`` (gains one a
            joint, the undriven ones' unused).
    """

    driven: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        model, rows = self.model, _joint_rows(self.model)
        joints_q = q[7:] if model.floating_base else q
        holding = driven_torques(model, q, np.zeros(len(v)), np.zeros(int(self.driven.sum())), self.driven)
        law = np.zeros(len(v))
        law[rows] = self.kp * (self.target - joints_q) - self.kd * v[rows]
        return np.where(self.driven, law + holding, 0.0)

    def twin_refusal(self) -> str | None:
        """Why there is no compiled twin: the C laws drive every joint (the undriven set is
        not in their parameters yet)."""
        return "joints without an actuator (the compiled laws drive every joint)"


@dataclass
class UnderactuatedComputedTorque(ComputedTorque):
    """:class:`~robodyn.sim.control.ComputedTorque` with zero torque on the joints not
    driven: only the driven joints follow the reference's law; the others move as that
    motion makes them.

    Attributes:
        driven: Which degrees of freedom an actuator drives, shape (nv,).
    """

    driven: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        model, rows = self.model, _joint_rows(self.model)
        q_d, v_d, a_d = self.reference(t)
        joints_q = q[7:] if model.floating_base else q
        command = np.zeros(len(v))
        command[rows] = a_d + self.kd * (v_d - v[rows]) + self.kp * (q_d - joints_q)
        return driven_torques(model, q, v, command[self.driven], self.driven)

    def twin_refusal(self) -> str | None:
        """Why there is no compiled twin: the C laws drive every joint (the undriven set is
        not in their parameters yet)."""
        return "joints without an actuator (the compiled laws drive every joint)"
