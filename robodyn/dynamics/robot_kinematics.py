"""The :class:`~robodyn.dynamics.robot.Robot`'s kinematics, limits and configurations, energies and
centroidal quantities: thin methods over :mod:`~robodyn.dynamics.kinematics`,
:mod:`~robodyn.dynamics.configurations`, :mod:`~robodyn.dynamics.energies` and
:mod:`~robodyn.dynamics.centroidal` (conventions: :mod:`robodyn.dynamics.robot`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from robodyn.common.text import quoted
from robodyn.dynamics import centroidal, configurations, energies, kinematics, mujoco_state
from robodyn.exceptions import InputError

if TYPE_CHECKING:
    from robodyn.dynamics.dofs import Dof
    from robodyn.dynamics.handle import ModelHandle
    from robodyn.dynamics.robot import Robot
    from robodyn.urdf.source_type import URDFSource


class RobotKinematics:
    """Where the robot is and how far it may go: a part of :class:`~robodyn.dynamics.robot.Robot`."""

    handle: ModelHandle
    dofs: tuple[Dof, ...]
    source: URDFSource

    # ----------------------------------------------------------------------------------
    # Energies (robodyn.dynamics.energies)
    # ----------------------------------------------------------------------------------
    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
        """Kinetic energy ``½ vᵀ M(q) v`` in [J]: a float, or shape (N,) for a batch.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        """
        return energies.kinetic_energy(self.handle, q, v)

    def potential_energy(self, q: np.ndarray) -> float | np.ndarray:
        """Gravitational potential energy ``−Σ m_i gᵀ p_i`` in [J]: a float, or shape (N,).

        Zero when every centre of mass is at height zero (for the default gravity).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
        """
        return energies.potential_energy(self.handle, q)

    # ----------------------------------------------------------------------------------
    # Kinematics (robodyn.dynamics.kinematics)
    # ----------------------------------------------------------------------------------
    @property
    def frame_names(self) -> list[str]:
        """Names of every frame: links, joints and fixed frames of the URDF."""
        return list(self.handle.frames)

    @property
    def frame_ids(self) -> dict[str, int]:
        """Pinocchio index of every frame, by name (a copy)."""
        return dict(self.handle.frames)

    def frame_id(self, frame: str) -> int:
        """Pinocchio index of a frame (link, joint or fixed frame) by name.

        Args:
            frame: The frame's name.

        Raises:
            FrameError: If the robot has no such frame (with the closest names).
        """
        return kinematics.frame_id(self.handle, frame)

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Position of a frame's origin in the world frame, shape (3,) or (N, 3), in [m]
        (:func:`robodyn.dynamics.kinematics.frame_position`)."""
        return kinematics.frame_position(self.handle, q, frame)

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Jacobian of a frame, shape (6, nv) or (N, 6, nv): linear rows then angular, in
        world-aligned axes at the frame's origin (:func:`robodyn.dynamics.kinematics.frame_jacobian`)."""
        return kinematics.frame_jacobian(self.handle, q, frame)

    def frame_bias_acceleration(self, q: np.ndarray, v: np.ndarray, frame: str) -> np.ndarray:
        """``J̇(q, v) v`` of a frame's origin, world axes, shape (3,), in [m/s²]
        (:func:`robodyn.dynamics.kinematics.frame_bias_acceleration`)."""
        return kinematics.frame_bias_acceleration(self.handle, q, v, frame)

    def wrench_torques(self, q: np.ndarray, frame: str, wrench: np.ndarray) -> np.ndarray:
        """Joint torques ``J(q)ᵀ w`` of a wrench (force [N], torque [N m], world axes) on a
        frame's origin, shape (nv,) (:func:`robodyn.dynamics.kinematics.wrench_torques`)."""
        return kinematics.wrench_torques(self.handle, q, frame, wrench)

    def integrate(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """The configuration reached from ``q`` along the velocity ``dq`` in unit time
        (:func:`robodyn.dynamics.kinematics.integrate`: SE(3) for a floating base).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            dq: The displacement, a velocity applied for unit time, shape (nv,) or (N, nv), in [rad] / [m].
        """
        return kinematics.integrate(self.handle, q, dq)

    # ----------------------------------------------------------------------------------
    # Limits and configurations (robodyn.dynamics.configurations)
    # ----------------------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        """Lower position limits per degree of freedom, shape (nv,), in [rad] or [m].

        The six base coordinates of a floating base are unlimited (-inf).
        """
        return configurations.lower_limits(self.dofs)

    @property
    def upper_limits(self) -> np.ndarray:
        """Upper position limits per degree of freedom, shape (nv,), in [rad] or [m]."""
        return configurations.upper_limits(self.dofs)

    def neutral_configuration(self) -> np.ndarray:
        """Pinocchio's neutral configuration (zero joint positions, the base at the origin,
        unrotated), shape (nq,); the robot's start is :meth:`default_configuration`."""
        return configurations.neutral_configuration(self.handle)

    def default_configuration(self, *, keyframe: str | None = None) -> np.ndarray:
        """The robot's start, shape (nq,): a floating base where the file puts it (MJCF:
        the free body's pose, MuJoCo's ``qpos0``), the joints at zero clipped into their
        position limits; every default start (simulations, contact runs, the CLI's
        ``q0``, the viewer) is this one
        (:func:`robodyn.dynamics.configurations.default_configuration`).

        Args:
            keyframe: The name of one of the MJCF file's ``<keyframe>`` s: its ``qpos``
                as robodyn's ``q`` (:meth:`from_mujoco`; unclipped, as MuJoCo starts it).

        Raises:
            InputError: If the file has no keyframe of that name.
        """
        if keyframe is None:
            return configurations.default_configuration(self.handle, self.dofs, self.source.base_pose)
        keys = dict(self.source.keyframes)
        if keyframe not in keys:
            known = ", ".join(quoted(name) for name in keys) or "none"
            raise InputError("keyframe", f"one of the file's MJCF keyframes ({known})", quoted(keyframe))
        return mujoco_state.from_mujoco(cast("Robot", self), np.array(keys[keyframe]))[0]

    def physical_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Position limits of the joints (floating base excluded), placeholders and empty
        ranges as ±inf: ``(lower, upper)``, each of shape (nv,) or (nv − 6,)
        (:func:`robodyn.dynamics.configurations.physical_limits`)."""
        return configurations.physical_limits(self.dofs)

    def floating_configuration(self, position, rpy, joints=None) -> np.ndarray:
        """A floating-base ``q`` (nq,) from the base position in [m], its roll, pitch, yaw
        in [rad] and the joint positions (default zeros)
        (:func:`robodyn.dynamics.configurations.floating_configuration`).

        Raises:
            InputError: For a fixed-base robot or wrong sizes.
        """
        return configurations.floating_configuration(self.handle, position, rpy, joints)

    def random_configuration(self, rng: np.random.Generator, count: int | None = None) -> np.ndarray:
        """Configurations drawn uniformly within the joint limits, in a physical range,
        shape (nq,) or (count, nq) (:func:`robodyn.dynamics.configurations.random_configuration`).

        Raises:
            InputError: If ``count`` is not a non-negative integer.
        """
        return configurations.random_configuration(self.handle, self.dofs, rng, count)

    # ----------------------------------------------------------------------------------
    # Centroidal quantities (robodyn.dynamics.centroidal)
    # ----------------------------------------------------------------------------------
    def center_of_mass(self, q: np.ndarray) -> np.ndarray:
        """The moving bodies' centre of mass (a floating robot's: all of it) in [m], world
        axes, shape (3,) or (N, 3)
        (:func:`robodyn.dynamics.centroidal.center_of_mass`)."""
        return centroidal.center_of_mass(self.handle, q)

    def centroidal_momentum(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Linear [kg m/s] then angular momentum about the centre of mass [kg m²/s], world
        axes, shape (6,) or (N, 6) (:func:`robodyn.dynamics.centroidal.centroidal_momentum`)."""
        return centroidal.centroidal_momentum(self.handle, q, v)

    def centroidal_momentum_matrix(self, q: np.ndarray) -> np.ndarray:
        """``A_G(q)`` with ``h = A_G v``, shape (6, nv) or (N, 6, nv)
        (:func:`robodyn.dynamics.centroidal.centroidal_momentum_matrix`)."""
        return centroidal.centroidal_momentum_matrix(self.handle, q)
