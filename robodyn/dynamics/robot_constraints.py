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
        (:func:`robodyn.dynamics.constrained.forward_dynamics`)."""
        return constrained.forward_dynamics(cast("Robot", self), q, v, tau, constraints)

    def contact_inverse_dynamics(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray, constraints: object = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(tau, λ)``: the least-norm ``λ`` that carries the unactuated coordinates, ``tau``
        the rest (:func:`robodyn.dynamics.constrained.contact_inverse_dynamics`)."""
        return constrained.contact_inverse_dynamics(cast("Robot", self), q, v, a, constraints)

    def constraint_jacobian(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J(q)``, shape (m, nv) or (N, m, nv) (:func:`robodyn.dynamics.constrained.constraint_jacobian`)."""
        return constrained.constraint_jacobian(cast("Robot", self), q, constraints)

    def constraint_drift(self, q: np.ndarray, v: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J̇(q, v) v``, shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_drift`)."""
        return constrained.constraint_drift(cast("Robot", self), q, v, constraints)

    def constraint_residual(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``Φ(q)`` in [m] / [rad], shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_residual`)."""
        return constrained.constraint_residual(cast("Robot", self), q, constraints)

    def constraint_rank(self, q: np.ndarray, constraints: object = None) -> int:
        """Independent rows of the constraints at ``q`` (nq,) (:func:`robodyn.dynamics.constrained.constraint_rank`)."""
        return constrained.constraint_rank(cast("Robot", self), q, constraints)
