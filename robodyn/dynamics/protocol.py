"""The dynamics protocol: what :class:`robodyn.Robot` and the compiled robot both answer.

:class:`Dynamics` lists the methods shared by the Pinocchio-backed :class:`robodyn.Robot` and
:class:`robodyn.compiled.CompiledRobot`, with one signature each (the same parameter names,
kinds and defaults: a test compares them with :func:`inspect.signature`), so code written
against it (a controller, a simulator, an optimiser) takes either engine. The shape rules
are the same for every method: one state as 1-D arrays gives one result, a stack (one state a
row) gives a stack.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Dynamics(Protocol):
    """A robot's rigid-body dynamics and frame kinematics (see the module).

    Attributes:
        name: The robot's name.
        nq: Size of a configuration ``q``.
        nv: Size of a velocity ``v`` (and of ``a``, ``tau``).
        joint_names: The order of the coordinates.
    """

    @property
    def name(self) -> str: ...

    @property
    def nq(self) -> int: ...

    @property
    def nv(self) -> int: ...

    @property
    def joint_names(self) -> list[str]: ...

    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, joint_friction: bool = False) -> np.ndarray:
        """Joint torques ``tau = M a + C v + G`` (plus the joints' friction torques with
        ``joint_friction``), shape (nv,) or (N, nv), in [N m] / [N].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
            joint_friction: Add the joints' friction torques ``b v + f sign(v)`` (``sign(0) = 0``).
        """
        ...

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint accelerations ``a = M⁻¹ (tau − C v − G)``, shape (nv,) or (N, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            tau: Joint torques / forces, shape (nv,) or (N, nv), in [N m] / [N].
        """
        ...

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``M(q)``, shape (nv, nv) or (N, nv, nv), in [kg m²] / [kg].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
        """
        ...

    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v)`` with ``dM/dt = C + Cᵀ``, shape (nv, nv) or (N, nv, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        """
        ...

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``, shape (nv,) or (N, nv), in [N m] / [N].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        """
        ...

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """``G(q)``, shape (nv,) or (N, nv), in [N m] / [N].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
        """
        ...

    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂τ/∂q, ∂τ/∂v, M)``, each (nv, nv) or (N, nv, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        ...

    def forward_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂q̈/∂q, ∂q̈/∂v, M⁻¹)``, each (nv, nv) or (N, nv, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            tau: Joint torques / forces, shape (nv,) or (N, nv), in [N m] / [N].
        """
        ...

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """A frame's origin in the world frame, shape (3,) or (N, 3), in [m].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
        """
        ...

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """A frame's Jacobian (linear rows then angular, world-aligned axes at its origin),
        shape (6, nv) or (N, 6, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
        """
        ...


#: The methods of :class:`Dynamics` (what a test compares between the engines).
METHODS = (
    "inverse_dynamics",
    "forward_dynamics",
    "mass_matrix",
    "coriolis_matrix",
    "nonlinear_effects",
    "gravity",
    "inverse_dynamics_derivatives",
    "forward_dynamics_derivatives",
    "frame_position",
    "frame_jacobian",
)

__all__ = ["METHODS", "Dynamics"]
