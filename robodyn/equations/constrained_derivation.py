"""The derivation with multipliers: a small robot under constraints, from ``Φ(q) = 0`` to ``λ``.

After the Lagrangian derivation of :mod:`robodyn.equations.derivation` (``M``, ``C q̇``,
``G``), the steps a lecture adds for constraints:

7. ``Φ(q) = 0``: each constraint's ends from the reference's forward kinematics in closed
   form (:mod:`robodyn.equations.constrained_kinematics`), and the rows: a point anchor's
   ``p₁(q) − p₂(q)`` (two links: a loop closure; or a link and the world), a frictionless
   contact's ``n·(p(q) − c)``, a weld's ``p₁ − p₂`` and ``log(R₁ R₂ᵀ) = θ a``, shown as
   ``sin θ a = ½ vee(R₁ R₂ᵀ − R₂ R₁ᵀ)`` (the same zeros below a half turn). A row that is
   ``0 = 0`` for every ``q`` (a planar linkage's out-of-plane row; a weld's rotation row
   whose angular velocity is 0) is dropped and said so: its multiplier is zero;
8. ``J``: ``∂Φ/∂q``, except a weld's rotation rows, whose ``J`` is the relative angular
   velocity's Jacobian (``ω₁ − ω₂ = J q̇``, world axes), as robodyn's numeric ``J``
   (:mod:`robodyn.constraints.algebra`): it is not the derivative of ``log(R₁ R₂ᵀ)``
   (they agree where ``Φ = 0``); and ``J̇ q̇ = Σ_k ∂(J q̇)/∂q_k q̇_k`` (the rows'
   acceleration at ``q̈ = 0``);
9. ``M q̈ + C q̇ + G = τ + Jᵀ λ`` with ``J q̈ + J̇ q̇ = 0``: the KKT system
   ``[[M, −Jᵀ], [J, 0]] (q̈, λ) = (τ − C q̇ − G, −J̇ q̇)``;
10. eliminating ``q̈``: ``λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇)`` in closed form
    when it is small enough to read (at most :data:`CLOSED_FORM_JOINTS` joints and
    :data:`CLOSED_FORM_ROWS` rows, ``J M⁻¹ Jᵀ`` not singular for every ``q``); else ``λ`` is stated as the
    KKT system's (least-norm) solution.

The worked example is the RP arm whose tip slides without friction on the wall ``x = c``
(``PointContact("end_effector", normal=(−1, 0, 0), friction=0, plane_point=(c, 0, 0))``):
``λ`` is the wall's normal force. A four-bar's loop (``PointAnchor`` between the coupler
and the rocker) gives its two in-plane rows and the KKT system. A sticking contact
(friction > 0: its tangential rows hold a velocity, not a position) is refused. Numbers
are exact (the file's as rationals); no Pinocchio. :meth:`ConstrainedDerivation.solve`
evaluates the derivation's own matrices at a state, to check them against robodyn's
numeric dynamics.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp
from sympy.matrices.exceptions import NonInvertibleMatrixError

from robodyn import reference
from robodyn.common.text import identifier, printable
from robodyn.constraints import Constraint, FrameAnchor, PointContact, as_constraints
from robodyn.constraints.algebra import row_labels
from robodyn.equations.constrained_kinematics import EndFrame, Kinematics, sine_vector
from robodyn.equations.derivation import DerivationSteps, derive_steps
from robodyn.equations.derivation_latex import _names as _latex_names  # steps 1–6: q_1, dot q_1
from robodyn.exceptions import InputError
from robodyn.reference.constraints import bound
from robodyn.reference.symbolic import exact_matrix

#: Most joints for which ``λ`` is put in closed form (beyond: the KKT system).
CLOSED_FORM_JOINTS = 2
#: Most rows for which ``λ`` is put in closed form.
CLOSED_FORM_ROWS = 2
#: Relative cut-off of the KKT matrix's singular values in :meth:`ConstrainedDerivation.solve`.
RCOND = 1e-11


@dataclass(frozen=True)
class ConstrainedDerivation:
    """Steps 7–10 (see the module) after the robot's Lagrangian derivation.

    Attributes:
        steps: Steps 1–6 (:func:`robodyn.equations.derivation.derive_steps`).
        constraints: The constraints.
        points: Each constraint's two points in the world, ``(p₁(q), p₂(q))`` (3 × 1 each),
            in [m] (a contact's second: its plane point).
        labels: ``(constraint, component, unit)`` of every row
            (:func:`robodyn.constraints.algebra.row_labels`).
        kept: Indices (into ``labels``) of the rows derived; the others are ``0 = 0``.
        phi: ``Φ(q)`` of the kept rows (rows × 1), in [m].
        J: ``∂Φ/∂q`` (rows × n).
        Jdot_qd: ``J̇ q̇`` (rows × 1), in [m/s²].
        tau: The torque symbols ``tau_<joint>`` (n).
        lam: ``λ(q, q̇, τ)`` of the kept rows in closed form (rows × 1), in [N]; ``None``
            when too large (then ``λ`` is the KKT system's solution).
        angular: Indices (into ``labels``) of the kept rows of welds' rotations: their
            ``Φ`` is shown as ``sin θ a`` and their ``J`` is the relative angular
            velocity's Jacobian (``ω₁ − ω₂ = J q̇``), not ``∂Φ/∂q``.
        relative_rotations: Each weld's ``R₁(q) R₂(q)ᵀ`` (3 × 3), in order.
    """

    steps: DerivationSteps
    constraints: tuple[Constraint, ...]
    points: tuple[tuple[sp.Matrix, sp.Matrix], ...]
    labels: tuple[tuple[str, str, str], ...]
    kept: tuple[int, ...]
    phi: sp.Matrix
    J: sp.Matrix
    Jdot_qd: sp.Matrix
    tau: tuple[sp.Symbol, ...]
    lam: sp.Matrix | None
    angular: tuple[int, ...] = ()
    relative_rotations: tuple[sp.Matrix, ...] = ()

    @property
    def constraint(self) -> Constraint:
        """The first constraint."""
        return self.constraints[0]

    @property
    def point(self) -> sp.Matrix:
        """The first constraint's first point ``p(q)`` (3 × 1), in [m]."""
        return self.points[0][0]

    @property
    def dropped(self) -> tuple[tuple[str, str, str], ...]:
        """The rows ``0 = 0`` for every ``q`` (their multipliers are zero)."""
        return tuple(label for index, label in enumerate(self.labels) if index not in self.kept)

    def _numbers(self, matrix: sp.Matrix, q: Sequence[float], qd: Sequence[float], tau: Sequence[float]) -> np.ndarray:
        values = dict(zip((*self.steps.q, *self.steps.qd, *self.tau), (*q, *qd, *tau), strict=True))
        return np.array(matrix.xreplace({k: sp.Float(float(v), 17) for k, v in values.items()}).evalf(17), dtype=float)

    def solve(self, q: Sequence[float], qd: Sequence[float], tau: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        """``q̈`` (n,) and ``λ`` (every row, the dropped ones 0) of the derivation's own
        KKT system at one state, by least squares (the least-norm ``λ`` of redundant rows).

        Args:
            q, qd, tau: The state and the torques, in the order of ``steps.joint_names``.
        """
        n, m = len(self.steps.q), self.J.rows
        mass = self._numbers(self.steps.M, q, qd, tau)
        jacobian = self._numbers(self.J, q, qd, tau).reshape(m, n)
        force = np.asarray(tau, float) - self._numbers(self.steps.Cv + self.steps.G, q, qd, tau).ravel()
        drift = self._numbers(self.Jdot_qd, q, qd, tau).ravel()
        kkt = np.block([[mass, -jacobian.T], [jacobian, np.zeros((m, m))]])
        solution = np.linalg.lstsq(kkt, np.concatenate([force, -drift]), rcond=RCOND)[0]
        lam = np.zeros(len(self.labels))
        lam[list(self.kept)] = solution[n:]
        return solution[:n], lam

    def multipliers(self, q: Sequence[float], qd: Sequence[float], tau: Sequence[float]) -> np.ndarray:
        """``λ`` at one state (every row, the dropped ones 0), shape (rows,): the closed form's
        when there is one, else :meth:`solve`'s.

        Args:
            q, qd, tau: The state and the torques, in the order of ``steps.joint_names``.
        """
        if self.lam is None:
            return self.solve(q, qd, tau)[1]
        lam = np.zeros(len(self.labels))
        lam[list(self.kept)] = self._numbers(self.lam, q, qd, tau).ravel()
        return lam


def _supported(constraints: Sequence[Constraint]) -> None:
    """Refuse a sticking contact: its tangential rows hold a velocity, not a position."""
    for index, constraint in enumerate(constraints):
        if isinstance(constraint, PointContact) and constraint.rows != 1:
            raise InputError(
                f"constraints[{index}]" if len(constraints) > 1 else "constraint",
                "a PointAnchor, a FrameAnchor (weld) or a frictionless PointContact: a sticking contact's "
                "tangential rows hold a velocity, not a position, and are not derived (with friction 0 its "
                "normal row is; without constraints, the open tree's derivation)",
                f"a point contact with friction {constraint.friction:.6g}",
            )


def _rows(constraint: Constraint, first: EndFrame, second: EndFrame) -> tuple[sp.Matrix, sp.Matrix | None]:
    """``Φ(q)`` of a constraint from its two ends, and a weld's relative angular velocity
    ``ω₁ − ω₂`` (its rotation rows' velocity; ``None`` for the others)."""
    gap = sp.expand(first.position - second.position)
    if isinstance(constraint, PointContact):
        normal = exact_matrix(np.array(constraint.normal)[:, None], 1e-12)
        return sp.Matrix([sp.expand((normal.T * gap)[0])]), None
    if isinstance(constraint, FrameAnchor):
        relative = first.rotation * second.rotation.T
        return sp.Matrix.vstack(gap, sine_vector(relative)), sp.expand(first.omega - second.omega)
    return gap, None


def _refuse_constant_rows(rows: sp.Matrix, q: Sequence[sp.Symbol], constraints: Sequence[Constraint]) -> None:
    """Refuse a row that is a non-zero constant: a constraint no configuration satisfies."""
    labels = row_labels(constraints)
    for index in range(rows.rows):
        if rows[index] != 0 and not rows[index].free_symbols & set(q):
            name, component, _ = labels[index]
            raise InputError(
                "constraints",
                "constraints some configuration satisfies",
                f"row {printable(name)}.{component} of Φ is the constant {float(rows[index]):.6g} m for every q",
            )


def _closed_form(steps: DerivationSteps, jacobian: sp.Matrix, drift: sp.Matrix, tau: Sequence[sp.Symbol]) -> sp.Matrix | None:
    """``λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇)``, or ``None`` when ``J M⁻¹ Jᵀ`` is
    singular for every ``q`` (redundant rows, e.g. one constraint given twice: ``λ`` is then
    the KKT system's least-norm solution, :meth:`ConstrainedDerivation.solve`)."""
    mass_inverse_jt = steps.M.LUsolve(jacobian.T)
    free = steps.M.LUsolve(sp.Matrix(tau) - steps.Cv - steps.G)
    try:
        return (-(jacobian * mass_inverse_jt).LUsolve(jacobian * free + drift)).applyfunc(sp.simplify)
    except NonInvertibleMatrixError:
        return None


def derive_constrained(
    source: str | os.PathLike, constraints: object, *, gravity: Sequence[float] | None = None
) -> ConstrainedDerivation:
    """Work the derivation of a small fixed-base robot under constraints (steps 1–10).

    Args:
        source: Anything :func:`robodyn.load` takes (a fixed base, at most
            :data:`~robodyn.equations.derivation.MAX_MOVING_JOINTS` moving joints). Its
            file's own constraints (MJCF ``<equality>``) are not added: pass them.
        constraints: One constraint or several: :class:`~robodyn.constraints.PointAnchor`
            (between two links, or a link and the world), :class:`~robodyn.constraints.FrameAnchor`
            (a weld) and frictionless :class:`~robodyn.constraints.PointContact`.
        gravity: Gravity in the world frame, in [m/s²]; default ``(0, 0, -9.81)``.

    Raises:
        InputError: For a sticking contact, none, a link the robot does not have, rows no
            configuration satisfies, or a robot too large to work by hand.
    """
    given = as_constraints(constraints, "constraints")
    if not given:
        raise InputError("constraints", "at least one constraint", "none")
    _supported(given)  # refuse before any algebra
    model = reference.load(source, gravity=gravity)
    bounds, _ = bound(model, given)
    steps = derive_steps(source, gravity=gravity)
    kinematics = Kinematics(model, steps)
    ends = [(kinematics.end(b.first), kinematics.end(b.second)) for b in bounds]
    parts = [_rows(c, *pair) for c, pair in zip(given, ends, strict=True)]
    q, qd = sp.Matrix(steps.q), sp.Matrix(steps.qd)
    every = sp.Matrix.vstack(*(phi for phi, _ in parts))
    # each row's velocity J q̇: dΦ/dt, or (a weld's rotation rows) ω₁ − ω₂
    velocity: list[sp.Expr] = []
    for phi, omega in parts:
        velocity += [sp.expand((sp.Matrix([phi[i]]).jacobian(q) * qd)[0]) for i in range(3 if omega is not None else phi.rows)]
        velocity += list(omega) if omega is not None else []
    angular = tuple(i for i, (_, component, _) in enumerate(row_labels(given)) if component.startswith("m"))
    kept = tuple(i for i in range(every.rows) if (velocity[i] != 0 if i in angular else every[i] != 0))
    _refuse_constant_rows(every, steps.q, given)
    phi = every.extract(list(kept), [0])
    jacobian = sp.simplify(sp.Matrix([velocity[i] for i in kept]).jacobian(qd))
    drift = sp.expand((jacobian * qd).jacobian(q) * qd).applyfunc(lambda row: sp.trigsimp(sp.collect(row, list(qd))))
    taken = {str(s) for s in (*steps.q, *steps.qd, *steps.qdd)}
    tau = tuple(sp.Symbol(identifier(name, taken, prefix="tau_"), real=True) for name in steps.joint_names)
    lam = None
    if len(steps.q) <= CLOSED_FORM_JOINTS and len(kept) <= CLOSED_FORM_ROWS:
        lam = _closed_form(steps, jacobian, drift, tau)
    points = tuple((first.position, second.position) for first, second in ends)
    rotations = tuple(
        sp.simplify(first.rotation * second.rotation.T)
        for c, (first, second) in zip(given, ends, strict=True)
        if isinstance(c, FrameAnchor)
    )
    labels = tuple(row_labels(given))
    angular_kept = tuple(i for i in kept if i in angular)
    return ConstrainedDerivation(steps, given, points, labels, kept, phi, jacobian, drift, tau, lam, angular_kept, rotations)


def readable(matrix: sp.Matrix, precision: int) -> sp.Matrix:
    """Exact numbers as floats of ``precision`` digits, products of constants multiplied out
    (in a fraction's numerator and denominator apart).

    Args:
        matrix: A matrix of the derivation.
        precision: Significant digits of its numbers.
    """

    def expanded(entry: sp.Expr) -> sp.Expr:
        numerator, denominator = sp.fraction(sp.together(entry))
        return sp.expand(numerator) / sp.expand(denominator)

    return matrix.evalf(17).applyfunc(expanded).evalf(precision)


def _row_names(derivation: ConstrainedDerivation, indices: Sequence[int]) -> str:
    return ", ".join(f"{printable(name)}.{component}" for name, component, _ in (derivation.labels[i] for i in indices))


def to_text(derivation: ConstrainedDerivation, *, precision: int = 6) -> str:
    """Steps 7–10 as plain text (steps 1–6: :func:`robodyn.equations.render_derivation.to_text`).

    Args:
        derivation: The derivation.
        precision: Significant digits of the printed numbers.
    """

    def show(matrix: sp.Matrix) -> list[str]:
        matrix = readable(matrix, precision)
        rows = (matrix.row(i) for i in range(matrix.rows))
        return [f"    {printable(sp.sstr(row[0] if row.cols == 1 else list(row)))}" for row in rows]

    lines = [f"constraint: {printable(str(c))}" for c in derivation.constraints]
    lines += ["", "step 7: Φ(q) = 0, with the constrained points p₁(q), p₂(q) ="]
    for first, second in derivation.points:
        lines += [*show(first), "  and", *show(second)]
    for rotation in derivation.relative_rotations:
        lines += ["  a weld's R₁(q) R₂(q)ᵀ =", *show(rotation)]
    lines += [f"  Φ(q) = p₁ − p₂ (rows {_row_names(derivation, derivation.kept)}) ="]
    if derivation.angular:
        lines[-1] = (
            f"  Φ(q) = p₁ − p₂, and for rows {_row_names(derivation, derivation.angular)} log(R₁ R₂ᵀ) = θ a, shown as "
            f"sin θ a = ½ vee(R₁ R₂ᵀ − R₂ R₁ᵀ) (the same zeros for θ < π) (rows {_row_names(derivation, derivation.kept)}) ="
        )
    lines += show(derivation.phi)
    if derivation.dropped:
        dropped = [i for i in range(len(derivation.labels)) if i not in derivation.kept]
        lines.append(f"  rows {_row_names(derivation, dropped)}: 0 = 0 for every q (dropped; their λ is 0)")
    step8 = "step 8: J = ∂Φ/∂q ="
    if derivation.angular:
        step8 = (
            f"step 8: J = ∂Φ/∂q, except rows {_row_names(derivation, derivation.angular)}: the relative angular "
            "velocity's Jacobian (ω₁ − ω₂ = J q̇, world axes; not ∂Φ/∂q, equal to it where Φ = 0) ="
        )
    lines += [step8, *show(derivation.J), "  J̇ q̇ =", *show(derivation.Jdot_qd)]
    lines.append("step 9: M q̈ + C q̇ + G = τ + Jᵀ λ, with J q̈ + J̇ q̇ = 0: [[M, −Jᵀ], [J, 0]] (q̈, λ) = (τ − C q̇ − G, −J̇ q̇)")
    if derivation.lam is None:
        joints, rows = len(derivation.steps.q), len(derivation.kept)
        lines.append(
            f"step 10: λ ({rows} rows) and q̈ solve that system: λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇) "
            f"(put in closed form up to {CLOSED_FORM_JOINTS} joints and {CLOSED_FORM_ROWS} rows, here {joints} and {rows}; "
            "when rows are redundant, J M⁻¹ Jᵀ is singular and λ is the least-norm solution)"
        )
    else:
        lines += ["step 10: λ = −(J M⁻¹ Jᵀ)⁻¹ (J M⁻¹ (τ − C q̇ − G) + J̇ q̇) =", *show(derivation.lam)]
    return "\n".join(lines) + "\n"


def to_latex(derivation: ConstrainedDerivation, *, precision: int = 6) -> str:
    """Steps 7–10 as LaTeX ``align*`` lines (math only).

    Args:
        derivation: The derivation.
        precision: Significant digits of the printed numbers.
    """

    names = {**_latex_names(derivation.steps), **{t: rf"\tau_{{{k}}}" for k, t in enumerate(derivation.tau, 1)}}

    def latex(matrix: sp.Matrix) -> str:
        return sp.latex(readable(matrix, precision), symbol_names=names)

    points = [rf"p_{{{k + 1}}}(q) &= {latex(a)}, \quad {latex(b)} \\" for k, (a, b) in enumerate(derivation.points)]
    points += [rf"R_1 R_2^\top &= {latex(rotation)} \\" for rotation in derivation.relative_rotations]
    angular = (
        r"\ \text{(a weld's rotation rows: } \Phi = \sin\theta\, a \text{ of } \log(R_1 R_2^\top)\text{, } "
        r"J \dot q = \omega_1 - \omega_2\text{, not } \partial \Phi / \partial q\text{)}"
        if derivation.angular
        else ""
    )
    kkt = r"\begin{pmatrix} M & -J^\top \\ J & 0 \end{pmatrix} \begin{pmatrix} \ddot q \\ \lambda \end{pmatrix}"
    system = rf"{kkt} &= \begin{{pmatrix}} \tau - C \dot q - G \\ -\dot J \dot q \end{{pmatrix}}"
    lam = r"\lambda &= -(J M^{-1} J^\top)^{-1} \left(J M^{-1} (\tau - C \dot q - G) + \dot J \dot q\right)"
    return "\n".join(
        [
            r"\begin{align*}",
            *points,
            rf"\Phi(q) &= {latex(derivation.phi)} = 0 \\",
            rf"J = \frac{{\partial \Phi}}{{\partial q}}{angular} &= {latex(derivation.J)} \\",
            rf"\dot J \dot q &= {latex(derivation.Jdot_qd)} \\",
            r"M \ddot q + C \dot q + G &= \tau + J^\top \lambda, \quad J \ddot q + \dot J \dot q = 0 \\",
            rf"{system} \\",
            lam + ("" if derivation.lam is None else f" = {latex(derivation.lam)}"),
            r"\end{align*}",
        ]
    )


__all__ = [
    "CLOSED_FORM_JOINTS",
    "CLOSED_FORM_ROWS",
    "ConstrainedDerivation",
    "derive_constrained",
    "readable",
    "to_latex",
    "to_text",
]
