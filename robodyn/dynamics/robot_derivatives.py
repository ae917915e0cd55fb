"""The :class:`~robodyn.dynamics.robot.Robot`'s analytical derivatives: thin methods over
:mod:`~robodyn.dynamics.derivatives` (``q`` columns in the tangent space).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from robodyn.dynamics import derivatives
from robodyn.dynamics.inertia_rank import SUSPECT_INVERSE, refuse_singular, singular_error
from robodyn.exceptions import SingularMassMatrixError

if TYPE_CHECKING:
    from robodyn.dynamics.handle import ModelHandle
    from robodyn.dynamics.robot import Robot


class RobotDerivatives:
    """Derivatives of the dynamics: a part of :class:`~robodyn.dynamics.robot.Robot`."""

    handle: ModelHandle

    # ----------------------------------------------------------------------------------
    # Derivatives (robodyn.dynamics.derivatives): q columns in the tangent space
    # ----------------------------------------------------------------------------------
    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂τ/∂q, ∂τ/∂v, ∂τ/∂a = M)`` of inverse dynamics (Pinocchio's analytical RNEA
        derivatives; :func:`robodyn.dynamics.derivatives.inverse_dynamics_derivatives`).

        Derivatives in ``q`` are along :meth:`integrate` (Pinocchio's convention: the
        floating base's six columns are its displacements in the base frame).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).

        Returns:
            Three arrays of shape (nv, nv) or (N, nv, nv), in SI units (torque per unit of
            the coordinate).
        """
        return derivatives.inverse_dynamics_derivatives(self.handle, q, v, a)

    def forward_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ = M⁻¹)`` of forward dynamics (Pinocchio's analytical ABA
        derivatives; :func:`robodyn.dynamics.derivatives.forward_dynamics_derivatives`).

        Derivatives in ``q`` are along :meth:`integrate`, as for
        :meth:`inverse_dynamics_derivatives`.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

        Returns:
            Three arrays of shape (nv, nv) or (N, nv, nv), in SI units.

        Raises:
            SingularMassMatrixError: If ``M(q)`` is singular: massless moving bodies, or joints
                that together move no inertia at ``q`` (named, with the row of a batch).
        """
        robot = cast("Robot", self)
        try:
            result = derivatives.forward_dynamics_derivatives(self.handle, q, v, tau)
        except SingularMassMatrixError as error:  # non-finite: name the joints, if some move no inertia
            raise (error if error.joints else singular_error(robot, q)) from None
        refuse_singular(robot, q, result[2], SUSPECT_INVERSE)  # M⁻¹ of a round-off pivot? (rank looked at only then)
        return result
