"""Inverse dynamics as a compact program: the recursive Newton–Euler algorithm, symbolically.

``tau = M a + C v + G`` from the compact equations needs all of ``M`` (O(n²) work);
the Newton–Euler recursion gives ``tau`` in O(n): a forward pass of angular velocities,
angular accelerations and origin accelerations (gravity enters as an upward acceleration
of the base), a backward pass of each subtree's force and moment, each projected on its
joint's axis. It is written here in the conventions of
:mod:`robodyn.equations.compact` (every quantity in its own body's frame, constants as
the URDF gives them, rotation entries exact only within ``snap`` of 0, ±1, ±½, ...), as
assignments in evaluation order; a variable is made only for a non-trivial expression.

No Pinocchio here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn.equations.compact import trivial
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import axis_rotation, exact_matrix


@dataclass
class NewtonEuler:
    """``tau`` of the reference's bodies as assignments then output expressions.

    Attributes:
        q, qd, qdd: One symbol per body (its joint's coordinate and rates).
        assignments: ``(symbol, expression)`` pairs in evaluation order.
        tau: One expression per body.
    """

    q: list[sp.Symbol]
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    assignments: list[tuple[sp.Symbol, sp.Expr]]
    tau: list[sp.Expr]


class _Program:
    def __init__(self) -> None:
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []

    def let(self, expr: sp.Expr) -> sp.Expr:
        expr = sp.expand(expr)
        if trivial(expr):
            return expr
        symbol = sp.Symbol(f"r{len(self.assignments)}", real=True)
        self.assignments.append((symbol, expr))
        return symbol

    def vector(self, values: sp.Matrix) -> sp.Matrix:
        return sp.Matrix([self.let(value) for value in values])


def derive_newton_euler(robot: ReferenceRobot, *, snap: float = 1e-15) -> NewtonEuler:
    """``tau(q, q̇, q̈)`` of every body of a reference robot (mimic joints as bodies of their own).

    Args:
        robot: From :mod:`robodyn.reference` (its tree's bodies are used as they are).
        snap: Tolerance for exact rotation and axis entries.
    """
    bodies = robot.tree.bodies
    count = len(bodies)
    q = [sp.Symbol(f"q{b}", real=True) for b in range(count)]
    qd = [sp.Symbol(f"qd{b}", real=True) for b in range(count)]
    qdd = [sp.Symbol(f"qdd{b}", real=True) for b in range(count)]
    program = _Program()
    zero = sp.zeros(3, 1)
    base_acc = exact_matrix(-robot.gravity_vector[:, None], 0.0)
    # Every entry is set (parents first) before it is read.
    R: list[sp.Matrix] = [zero] * count
    t: list[sp.Matrix] = [zero] * count
    axis: list[sp.Matrix] = [zero] * count
    w, dw, acc = [zero] * count, [zero] * count, [zero] * count
    for b, body in enumerate(bodies):
        axis[b] = exact_matrix(body.axis[:, None], snap)
        rotation = exact_matrix(body.origin[:3, :3], snap)
        translation = exact_matrix(body.origin[:3, 3:], 0.0)
        if body.revolute:
            c, s = program.let(sp.cos(q[b])), program.let(sp.sin(q[b]))
            R[b] = (rotation * axis_rotation(axis[b], c, s)).applyfunc(program.let)
            t[b] = translation
        else:
            R[b] = rotation
            t[b] = program.vector(translation + rotation * axis[b] * q[b])
        parent = body.parent
        w_p, dw_p = (zero, zero) if parent < 0 else (w[parent], dw[parent])
        a_p = base_acc if parent < 0 else acc[parent]
        Rt = R[b].T
        w_in = program.vector(Rt * w_p)
        origin = Rt * (a_p + dw_p.cross(t[b]) + w_p.cross(w_p.cross(t[b])))
        if body.revolute:
            w[b] = program.vector(w_in + axis[b] * qd[b])
            dw[b] = program.vector(Rt * dw_p + w_in.cross(axis[b] * qd[b]) + axis[b] * qdd[b])
            acc[b] = program.vector(origin)
        else:
            w[b] = w_in
            dw[b] = program.vector(Rt * dw_p)
            acc[b] = program.vector(origin + 2 * w_in.cross(axis[b] * qd[b]) + axis[b] * qdd[b])
    force, moment = [zero] * count, [zero] * count
    tau: list[sp.Expr] = [sp.Integer(0)] * count
    for b in reversed(range(count)):
        body = bodies[b]
        if body.mass != 0 or np.any(body.inertia):
            mass = exact_matrix(np.array([[body.mass]]), 0.0)[0]
            com = exact_matrix(body.com[:, None], 0.0)
            inertia = exact_matrix(body.inertia, 0.0)
            f = program.vector(mass * (acc[b] + dw[b].cross(com) + w[b].cross(w[b].cross(com))))
            force[b] = force[b] + f
            moment[b] = moment[b] + inertia * dw[b] + w[b].cross(inertia * w[b]) + com.cross(f)
        force[b], moment[b] = program.vector(force[b]), program.vector(moment[b])
        tau[b] = sp.expand((axis[b].T * (moment[b] if body.revolute else force[b]))[0])
        if body.parent >= 0:
            pushed = R[b] * force[b]
            force[body.parent] = force[body.parent] + pushed
            moment[body.parent] = moment[body.parent] + R[b] * moment[b] + t[b].cross(pushed)
    return NewtonEuler(q, qd, qdd, program.assignments, tau)
