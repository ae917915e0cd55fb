"""The derivation with multipliers: a small robot under one constraint, from ``Φ(q) = 0`` to ``λ(q, q̇, τ)``.

After the Lagrangian derivation of :mod:`robodyn.equations.derivation` (``M``, ``C q̇``,
``G``), the steps a lecture adds for a constraint:

7. ``Φ(q) = 0``: the constrained point ``p(q)`` from the reference's forward kinematics in
   closed form (:func:`robodyn.reference.symbolic.body_poses`), and the constraint's rows;
8. ``J = ∂Φ/∂q`` and ``J̇ q̇ = Σ_k ∂(J q̇)/∂q_k q̇_k`` (the rows' acceleration at ``q̈ = 0``);
9. ``M q̈ + C q̇ + G = τ + Jᵀ λ`` with ``J q̈ + J̇ q̇ = 0``;
10. eliminating ``q̈``: ``λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇)``, in closed form.

The worked example is the RP arm whose tip slides without friction on the wall ``x = c``
(``PointContact("end_effector", normal=(−1, 0, 0), friction=0, plane_point=(c, 0, 0))``):
``λ`` is the wall's normal force. Constraints whose ``J`` is ``∂Φ/∂q``: a frictionless
contact (1 row) or a point anchor to the world (3 rows). Numbers are exact (the URDF's as
rationals); no Pinocchio.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn import reference
from robodyn.common.text import identifier, printable
from robodyn.constraints import Constraint, PointAnchor, PointContact, check_frames
from robodyn.equations.derivation import DerivationSteps, derive_steps
from robodyn.exceptions import InputError
from robodyn.reference.constraints import link_frames
from robodyn.reference.symbolic import body_coordinates, body_poses, exact_matrix


@dataclass(frozen=True)
class ConstrainedDerivation:
    """Steps 7–10 (see the module) after the robot's Lagrangian derivation.

    Attributes:
        steps: Steps 1–6 (:func:`robodyn.equations.derivation.derive_steps`).
        constraint: The constraint.
        point: The constrained point in the world, ``p(q)`` (3 × 1), in [m].
        phi: ``Φ(q)`` (rows × 1), in [m].
        J: ``∂Φ/∂q`` (rows × n).
        Jdot_qd: ``J̇ q̇`` (rows × 1), in [m/s²].
        tau: The torque symbols ``tau_<joint>`` (n).
        lam: ``λ(q, q̇, τ)`` in closed form (rows × 1), in [N].
    """

    steps: DerivationSteps
    constraint: Constraint
    point: sp.Matrix
    phi: sp.Matrix
    J: sp.Matrix
    Jdot_qd: sp.Matrix
    tau: tuple[sp.Symbol, ...]
    lam: sp.Matrix

    def multipliers(self, q: Sequence[float], qd: Sequence[float], tau: Sequence[float]) -> np.ndarray:
        """``λ`` of the closed form at one state (numbers), shape (rows,)."""
        values = dict(zip((*self.steps.q, *self.steps.qd, *self.tau), (*q, *qd, *tau), strict=True))
        return np.array(self.lam.xreplace({k: sp.Float(v, 17) for k, v in values.items()}).evalf(17), dtype=float).ravel()


def _point(model: reference.ReferenceRobot, steps: DerivationSteps, link: str, local: Sequence[float]) -> sp.Matrix:
    """A point fixed in ``link`` (``local`` in its frame) in world coordinates, as a function of ``q``."""
    body, to_link = link_frames(model)[link]
    position = to_link[:3, :3] @ np.asarray(local, float) + to_link[:3, 3]
    offset = exact_matrix(position[:, None], 1e-12)
    if body < 0:
        return offset
    theta, _ = body_coordinates(model, list(steps.q), list(steps.qd))
    rotations, positions, _ = body_poses(model, theta)
    return sp.simplify(positions[body] + rotations[body] * offset)


def _rows(constraint: Constraint, point: sp.Matrix) -> sp.Matrix:
    """``Φ(q)`` of a constraint whose ``J`` is ``∂Φ/∂q``, or an :class:`InputError`."""
    if isinstance(constraint, PointContact) and constraint.rows == 1:
        normal = exact_matrix(np.array(constraint.normal)[:, None], 1e-12)
        plane = exact_matrix(np.array(constraint.plane_point)[:, None], 1e-12)
        return sp.Matrix([sp.expand((normal.T * (point - plane))[0])])
    if isinstance(constraint, PointAnchor) and constraint.frame2 is None and constraint.point2 is not None:
        return sp.expand(point - exact_matrix(np.array(constraint.point2)[:, None], 1e-12))
    raise InputError(
        "constraint",
        "a frictionless PointContact or a PointAnchor to a given world point (J = ∂Φ/∂q)",
        printable(str(constraint)),
    )


def derive_constrained(
    source: str | os.PathLike, constraint: Constraint, *, gravity: Sequence[float] | None = None
) -> ConstrainedDerivation:
    """Work the derivation of a small fixed-base robot under one constraint (steps 1–10).

    Args:
        source: Anything :func:`robodyn.load` takes (a fixed base, at most
            :data:`~robodyn.equations.derivation.MAX_MOVING_JOINTS` moving joints).
        constraint: A frictionless :class:`~robodyn.constraints.PointContact` or a
            :class:`~robodyn.constraints.PointAnchor` to a given world point.
        gravity: Gravity in the world frame, in [m/s²]; default ``(0, 0, -9.81)``.

    Raises:
        InputError: For another constraint, a link the robot does not have, or a robot
            too large to work by hand.
    """
    _rows(constraint, sp.zeros(3, 1))  # refuse an unsupported constraint before any algebra
    model = reference.load(source, gravity=gravity)
    check_frames([constraint], list(model.spec.links), model.name)
    steps = derive_steps(source, gravity=gravity)
    if isinstance(constraint, PointContact):
        link, local = constraint.frame, constraint.point
    else:
        assert isinstance(constraint, PointAnchor)  # _rows took no other kind
        link, local = constraint.frame1, constraint.point1
    point = _point(model, steps, link, local)
    phi = _rows(constraint, point)
    q, qd = sp.Matrix(steps.q), sp.Matrix(steps.qd)
    jacobian = sp.simplify(phi.jacobian(q))
    drift = sp.simplify((jacobian * qd).jacobian(q) * qd)
    taken = {str(s) for s in (*steps.q, *steps.qd, *steps.qdd)}
    tau = tuple(sp.Symbol(identifier(name, taken, prefix="tau_"), real=True) for name in steps.joint_names)
    mass_inverse_jt = steps.M.LUsolve(jacobian.T)
    free = steps.M.LUsolve(sp.Matrix(tau) - steps.Cv - steps.G)
    delassus = jacobian * mass_inverse_jt
    lam = (-delassus.LUsolve(jacobian * free + drift)).applyfunc(sp.simplify)
    return ConstrainedDerivation(steps, constraint, point, phi, jacobian, drift, tau, lam)


def to_text(derivation: ConstrainedDerivation) -> str:
    """Steps 7–10 as plain text (steps 1–6: :func:`robodyn.equations.render_derivation.to_text`)."""

    def show(matrix: sp.Matrix) -> str:
        rows = (matrix.row(i) for i in range(matrix.rows))
        return "\n".join(f"    {printable(sp.sstr(row[0] if row.cols == 1 else list(row)))}" for row in rows)

    return "\n".join(
        [
            f"constraint: {printable(str(derivation.constraint))}",
            "",
            "step 7: Φ(q) = 0, with the constrained point p(q) =",
            show(derivation.point),
            "  Φ(q) =",
            show(derivation.phi),
            "step 8: J = ∂Φ/∂q =",
            show(derivation.J),
            "  J̇ q̇ =",
            show(derivation.Jdot_qd),
            "step 9: M q̈ + C q̇ + G = τ + Jᵀ λ, with J q̈ + J̇ q̇ = 0",
            "step 10: λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇) =",
            show(derivation.lam),
        ]
    )


def to_latex(derivation: ConstrainedDerivation) -> str:
    """Steps 7–10 as LaTeX ``align*`` lines (math only)."""
    latex = sp.latex
    return "\n".join(
        [
            r"\begin{align*}",
            rf"p(q) &= {latex(derivation.point)} \\",
            rf"\Phi(q) &= {latex(derivation.phi)} = 0 \\",
            rf"J = \frac{{\partial \Phi}}{{\partial q}} &= {latex(derivation.J)}, \quad \dot J \dot q = {latex(derivation.Jdot_qd)} \\",
            r"M \ddot q + C \dot q + G &= \tau + J^\top \lambda, \quad J \ddot q + \dot J \dot q = 0 \\",
            rf"\lambda &= -(J M^{{-1}} J^\top)^{{-1}} \left(J M^{{-1}} (\tau - C \dot q - G) + \dot J \dot q\right) = {latex(derivation.lam)}",
            r"\end{align*}",
        ]
    )


__all__ = ["ConstrainedDerivation", "derive_constrained", "to_latex", "to_text"]
