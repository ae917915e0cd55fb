"""The :class:`~robodyn.dynamics.robot.Robot` in other models' terms: the inertial-parameter regressor
(:mod:`~robodyn.dynamics.regressor`) and MuJoCo's state (:mod:`~robodyn.dynamics.mujoco_state`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, cast

import numpy as np

from robodyn.dynamics import mujoco_state
from robodyn.dynamics import regressor as identification

if TYPE_CHECKING:
    from robodyn.dynamics.handle import ModelHandle
    from robodyn.dynamics.robot import Robot


class RobotExchange:
    """Identification and MuJoCo's coordinates: a part of :class:`~robodyn.dynamics.robot.Robot`."""

    handle: ModelHandle

    # ----------------------------------------------------------------------------------
    # Identification (robodyn.dynamics.regressor)
    # ----------------------------------------------------------------------------------
    def regressor(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, friction: bool = False) -> np.ndarray:
        """The inertial-parameter regressor ``Y`` with ``Y @ inertial_parameters() == tau``.

        Per body (the links that move): m, m·c (3), inertia about the body origin in the
        body frame (Ixx, Ixy, Iyy, Ixz, Iyz, Izz); optional viscous and Coulomb friction
        columns per degree of freedom. See :func:`robodyn.dynamics.regressor.regressor`.

        Returns:
            Shape (nv, 10·n_bodies [+ 2·nv]) or (N, nv, …) for a batch.
        """
        return identification.regressor(self.handle, q, v, a, friction=friction)

    def inertial_parameters(self, *, friction: bool = False) -> np.ndarray:
        """The URDF's standard inertial parameters π, in :meth:`regressor`'s order.

        Args:
            friction: Append the joints' viscous then Coulomb friction coefficients (:attr:`joint_damping`,
                :attr:`joint_friction`).
        """
        return identification.inertial_parameters(self.handle, friction=friction)

    # ----------------------------------------------------------------------------------
    # MuJoCo's state (robodyn.dynamics.mujoco_state)
    # ----------------------------------------------------------------------------------
    def to_mujoco(self, q: np.ndarray, v: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None) -> tuple:
        """MuJoCo's ``(qpos, qvel)`` of ``(q, v)``: joints by name in MuJoCo's order, ``ref``
        offsets, the free joint's w-first quaternion and world linear velocity. See
        :mod:`robodyn.dynamics.mujoco_state` (``joint_names``: MuJoCo's order, needed
        unless the robot was read from MJCF).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), or ``None`` (then ``qvel`` is ``None``).
            joint_names: MuJoCo's joint names in its order (needed unless the robot was read from MJCF).
        """
        return mujoco_state.to_mujoco(cast("Robot", self), q, v, joint_names=joint_names)

    def from_mujoco(self, qpos: np.ndarray, qvel: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None) -> tuple:
        """robodyn's ``(q, v)`` of MuJoCo's ``(qpos, qvel)`` (the inverse of :meth:`to_mujoco`).

        Args:
            qpos: MuJoCo's positions, shape (nq,) or (N, nq).
            qvel: MuJoCo's velocities, shape (nv,) or (N, nv), or ``None``.
            joint_names: MuJoCo's joint names in its order (needed unless the robot was read from MJCF).
        """
        return mujoco_state.from_mujoco(cast("Robot", self), qpos, qvel, joint_names=joint_names)
