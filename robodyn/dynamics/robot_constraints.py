"""The :class:`~robodyn.dynamics.robot.Robot`'s constraints and constrained dynamics: thin methods over
:mod:`~robodyn.dynamics.constrained` (the rows: :mod:`robodyn.constraints.algebra`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from robodyn.constraints import Constraint, from_equalities
from robodyn.dynamics import constrained

if TYPE_CHECKING:
    from robodyn.dynamics.options import LoadOptions
    from robodyn.dynamics.robot import Robot
    from robodyn.urdf.sources import URDFSource


class RobotConstraints:
    """Closed loops, welds and contacts: a part of :class:`~robodyn.dynamics.robot.Robot`."""

    source: URDFSource
    options: LoadOptions

    # ----------------------------------------------------------------------------------
    # Constraints (robodyn.dynamics.constrained; the rows: robodyn.constraints.algebra).
    # ``constraints=None``: the robot's own (:attr:`constraints`).
    # ----------------------------------------------------------------------------------
    @property
    def constraints(self) -> tuple[Constraint, ...]:
        """The robot's constraints: its file's (MJCF ``<equality>``), then ``load(constraints=)``'s."""
        return (*from_equalities(self.source.equalities), *self.options.constraints)

    def constrained_forward_dynamics(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, constraints: object = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(a, λ)`` of ``M a + C v + G = tau + Jᵀ λ``, ``J a + J̇ v = 0`` (contacts bilateral;
        ``λ`` least-norm for a redundant set), shapes (nv,), (m,) or (N, nv), (N, m)
        (:func:`robodyn.dynamics.constrained.forward_dynamics`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            tau: Joint torques / forces, shape (nv,) or (N, nv), in [N m] / [N].
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.forward_dynamics(cast("Robot", self), q, v, tau, constraints)

    def contact_inverse_dynamics(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray, constraints: object = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(tau, λ)``: the least-norm ``λ`` that carries the unactuated coordinates, ``tau``
        the rest (:func:`robodyn.dynamics.constrained.contact_inverse_dynamics`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.contact_inverse_dynamics(cast("Robot", self), q, v, a, constraints)

    def constraint_jacobian(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J(q)``, shape (m, nv) or (N, m, nv) (:func:`robodyn.dynamics.constrained.constraint_jacobian`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.constraint_jacobian(cast("Robot", self), q, constraints)

    def constraint_drift(self, q: np.ndarray, v: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J̇(q, v) v``, shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_drift`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.constraint_drift(cast("Robot", self), q, v, constraints)

    def constraint_residual(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``Φ(q)`` in [m] / [rad], shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_residual`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit
                quaternion).
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.constraint_residual(cast("Robot", self), q, constraints)

    def constraint_rank(self, q: np.ndarray, constraints: object = None) -> int:
        """Independent rows of the constraints at ``q`` (nq,) (:func:`robodyn.dynamics.constrained.constraint_rank`).

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
                :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an
                iterable of them, or ``None`` for the robot's own (:attr:`constraints`).
        """
        return constrained.constraint_rank(cast("Robot", self), q, constraints)
