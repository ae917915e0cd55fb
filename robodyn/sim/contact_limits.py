"""Joint limits in a contact run: each position limit a one-sided contact on its joint.

A run on the ground with ``limits="enforce"`` solves its joints' position limits in the
**same complementarity problem** as its ground contacts (what MuJoCo does: a limit is one
more constraint row of its solver). The lower limit of joint coordinate ``j`` is the row

    λ ≥ 0,     u = v⁺_j + b ≥ 0,     λ u = 0

with the impulse ``λ`` [N m s] / [N s] acting on ``v_j`` alone (the upper limit: ``−v⁺_j``,
a negative torque); the bias ``b`` is the contact normal rows' (:mod:`robodyn.sim.contact`):
with the gap ``g = q_j − lower ≥ 0`` the joint may reach its limit within the step but not
cross it (``b = g / dt``, speculative), a joint past it is pushed back by ``β`` of the
overshoot a step (``b = β g / dt``). Stops are inelastic and frictionless.

**How it enters the solver**: a row is a cone of three rows whose normal row is the
limit's and whose two tangent rows are decoupled from everything (a Delassus diagonal equal
to the normal row's, no free velocity), in the step of a run without limits
(:func:`robodyn.sim.contact.contact_step` with ``limits``; its compiled path declines a
step with a row in reach). Their impulses are zero at every solution (sticking needs
``u_t = d p_t = 0``; slipping would need ``p_t`` against ``u_t = d p_t``), so the cone
reduces to ``λ ≥ 0`` and De Saxcé's term ``μ ‖u_t‖`` vanishes: the contact solver
(:func:`robodyn.sim.contact_solver.solve_impulses`, Pinocchio's ADMM and the exact polish)
solves the combined problem unchanged. A limit enters a step when its joint is within
reach of it, ``g < 2 dt (|v_j| + |v_free,j|) +`` :data:`REACH` (else its impulse is 0).
Effort limits saturate the applied torque, as ``limits="enforce"`` does without a ground.
"""

from __future__ import annotations

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.sim.limits import JointLimits

#: A limit row enters a step when its joint is this close to it (beyond the step's reach),
#: in [rad] or [m].
REACH = 1e-3


class LimitRows:
    """A robot's finite position limits as rows ``s (q_j − bound) ≥ 0`` (``s = +1`` lower,
    ``−1`` upper).

    Attributes:
        limits: The robot's :class:`~robodyn.sim.limits.JointLimits` (its efforts saturate).
        q_index, v_index: Each row's coordinate in ``q`` and in ``v``, shape (r,).
        bound: Each row's limit, (r,); sign: ``+1`` lower, ``−1`` upper, (r,).
        names: Each row's ``"<joint> lower"`` / ``"<joint> upper"``.
    """

    def __init__(self, robot: Robot) -> None:
        self.limits = limits = JointLimits(robot)
        count = len(limits.lower)
        q_start, v_start = robot.nq - count, robot.nv - count
        rows = [(i, bound, 1.0) for i, bound in enumerate(limits.lower) if np.isfinite(bound)]
        rows += [(i, bound, -1.0) for i, bound in enumerate(limits.upper) if np.isfinite(bound)]
        index = np.array([row[0] for row in rows], dtype=int)
        self.q_index, self.v_index = q_start + index, v_start + index
        self.bound = np.array([row[1] for row in rows], dtype=float)
        self.sign = np.array([row[2] for row in rows], dtype=float)
        dofs = robot.dofs[v_start:]
        self.names = [f"{dofs[i].joint} {'lower' if s > 0 else 'upper'}" for i, s in zip(index, self.sign, strict=True)]

    def gaps(self, q: np.ndarray) -> np.ndarray:
        """Each row's distance inside its limit, shape (r,), in [rad] or [m] (< 0: past it).

        Args:
            q: A configuration, shape (nq,).
        """
        return self.sign * (q[self.q_index] - self.bound)

    def torques(self, impulses: np.ndarray, dt: float, nv: int) -> np.ndarray:
        """The generalized torques of the rows' impulses (r,) [N m s] over ``dt``, shape (nv,).

        Args:
            impulses: The rows' impulses, shape (r,), in [N m s] or [N s].
            dt: The step they act over, in [s].
            nv: The robot's number of velocity coordinates.
        """
        out = np.zeros(nv)
        np.add.at(out, self.v_index, self.sign * impulses / dt)
        return out

    def near(self, q: np.ndarray, v: np.ndarray, free: np.ndarray, dt: float) -> np.ndarray:
        """The rows within reach of a step (module docstring), their indices (m,).

        Args:
            q: The configuration at the start, shape (nq,).
            v: The velocity at the start, shape (nv,), in [rad/s] or [m/s].
            free: The velocity after the step without constraint impulses, shape (nv,).
            dt: The step, in [s].
        """
        reach = 2 * dt * (np.abs(v) + np.abs(free))[self.v_index] + REACH
        return np.flatnonzero(self.gaps(q) < reach)

    def jacobian(self, near: np.ndarray, nv: int) -> np.ndarray:
        """The rows ``near`` as cones of the contact problem: three rows each (two
        decoupled tangent rows of zeros, then the normal row ``s e_j``), shape (3m, nv).

        Args:
            near: The rows' indices, shape (m,).
            nv: The robot's number of velocity coordinates.
        """
        out = np.zeros((3 * len(near), nv))
        out[3 * np.arange(len(near)) + 2, self.v_index[near]] = self.sign[near]
        return out


__all__ = ["REACH", "LimitRows"]
