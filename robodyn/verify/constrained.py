"""``robodyn check`` for robots with constraints: ``Φ``, ``J``, ``J̇ v``, ``v̇`` and ``λ`` of the
dynamics layer (Pinocchio's kinematics, robodyn's KKT solve) against the reference's
(its own kinematics, the KKT system solved whole by least squares).

The random states of :func:`robodyn.verify.check.check_robot` are not on the constraints'
manifold (``Φ ≠ 0``, ``J v ≠ 0``): both sides define every quantity there all the same,
so the comparison covers the whole state space, not only the closed configurations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.reference import constraints as reference_constraints

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

#: What each compared quantity is (``robodyn check``'s table).
DESCRIPTIONS = {
    "Phi": "constraint residual Phi(q)",
    "J": "constraint Jacobian J(q)",
    "Jdot_v": "constraint drift Jdot(q, v) v",
    "constrained_a": "constrained accelerations (KKT)",
    "lambda": "constraint multipliers lambda (KKT)",
}


def _largest(values: np.ndarray) -> float:
    return float(np.max(np.abs(values))) if values.size else 0.0


def constraint_values(
    robot: Robot, matched, q: np.ndarray, v: np.ndarray, tau: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray, float, list[str] | None]]:
    """The constraint quantities of both implementations at the states ``q`` (N, nq), ``v``
    and ``tau`` (N, nv): ``{name: (robodyn's, the reference's, floor, coordinate names)}``
    with the names of :data:`DESCRIPTIONS` (``floor``: the size a vanishing quantity is
    compared with).

    Args:
        robot: The robot (its :attr:`~robodyn.Robot.constraints` are compared).
        matched: The reference in the robot's coordinate order (``check``'s ``_Matched``).
        q, v, tau: The states.
    """
    constraints = robot.constraints
    model = matched.model
    q_ref, v_ref, tau_ref = matched.states(q, v, tau)
    phi_ref, jacobian_ref, drift_ref = reference_constraints.constraint_terms(model, q_ref, v_ref, constraints)
    jacobian_ref = jacobian_ref[:, :, matched.v_order]
    a_ref, lam_ref = reference_constraints.constrained_forward_dynamics(model, q_ref, v_ref, tau_ref, constraints)
    a, lam = robot.constrained_forward_dynamics(q, v, tau)
    dofs = [dof.name for dof in robot.dofs]
    speed, size = _largest(v), _largest(jacobian_ref)
    return {
        "Phi": (robot.constraint_residual(q), phi_ref, 1.0, None),
        "J": (robot.constraint_jacobian(q), jacobian_ref, 1.0, None),
        "Jdot_v": (robot.constraint_drift(q, v), drift_ref, size * speed**2, None),
        "constrained_a": (a, matched.from_reference(a_ref), 0.0, dofs),
        "lambda": (lam, lam_ref, _largest(tau), None),
    }


__all__ = ["DESCRIPTIONS", "constraint_values"]
