"""The lecture's RP arm derivation, as printed, as derived, and as a rigid body.

docs/rp-arm.md restates the lecture's revolute–prismatic arm: link 1 with
centre of mass at ``l1/2``, link 2 with its centre of mass at ``l1 + q2/2`` (half the joint
speed: not a rigid body), gravity ``(0, −g, 0)`` in the lecture's plane. This module gives,
in the lecture's symbols ``l1, m1, m2, Iz1, Iz2, g``:

- :func:`printed` — the result as printed on slide 34;
- :func:`derived` — the same energies through the symbolic Lagrangian machinery of
  :mod:`robodyn.reference.symbolic`, with the slide's potential-energy sign
  (``sign=+1``: ``U = m ḡ·P``, erratum 1) or the correct one (``sign=-1``);
- :func:`rigid` — the rigid-body arm robodyn generates (centre of mass at
  ``r2 = l1 + q2 + c2``), whose equations the URDF's dynamics must equal.

:data:`ERRATA` names each erratum and where it shows. No Pinocchio here.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from robodyn.reference.symbolic import SymbolicDynamics, lagrangian_dynamics

l1, m1, m2, Iz1, Iz2, g, c2 = sp.symbols("l1 m1 m2 Iz1 Iz2 g c2", positive=True)
q1, q2 = sp.symbols("q1 q2", real=True)
qd1, qd2 = sp.symbols("qd1 qd2", real=True)
qdd1, qdd2 = sp.symbols("qdd1 qdd2", real=True)
Q, QD, QDD = [q1, q2], [qd1, qd2], [qdd1, qdd2]

#: The errata of ``rp-arm.md``: number, name, and the terms of the printed result they touch.
ERRATA = {
    1: ("potential energy sign: U = m ḡ·P makes both entries of G(q) change sign", ("G",)),
    2: ("chain rule: the velocity-product term of tau1 is m2 (l1 + q2/2) q1' q2', not twice that", ("C",)),
    3: ("not a rigid body: a COM at l1 + q2/2 gives the slider an effective mass m2/4; a rigid link has m2", ("M",)),
}


def printed() -> sp.Matrix:
    """``tau`` exactly as printed on slide 34 (with its errata)."""
    r = l1 + q2 / 2
    tau1 = (m1 * l1**2 / 4 + Iz1 + m2 * r**2 + Iz2) * qdd1 + 2 * m2 * r * qd1 * qd2 - (m1 * l1 * g / 2 + m2 * g * r) * sp.cos(q1)
    tau2 = m2 / 4 * qdd2 - m2 / 2 * r * qd1**2 - m2 * g / 2 * sp.sin(q1)
    return sp.Matrix([tau1, tau2])


def _energies(com2_distance: sp.Expr, sign: int) -> tuple[sp.Expr, sp.Expr]:
    """Kinetic and potential energy of the two links (the lecture's slides 16-30)."""
    direction = sp.Matrix([sp.cos(q1), sp.sin(q1), 0])
    com1 = l1 / 2 * direction
    com2 = com2_distance * direction
    v1 = com1.jacobian(Q) * sp.Matrix(QD)
    v2 = com2.jacobian(Q) * sp.Matrix(QD)
    gravity = sp.Matrix([0, -g, 0])
    T = (m1 * (v1.T * v1)[0] + Iz1 * qd1**2 + m2 * (v2.T * v2)[0] + Iz2 * qd1**2) / 2
    U = sign * (m1 * (gravity.T * com1)[0] + m2 * (gravity.T * com2)[0])
    return sp.simplify(T), U


def derived(sign: int = -1) -> SymbolicDynamics:
    """The lecture's own (non-rigid) model through the Lagrangian machinery.

    Args:
        sign: ``-1`` for the correct ``U = −m ḡ·P``; ``+1`` for the slide's ``U = m ḡ·P``.
    """
    T, U = _energies(l1 + q2 / 2, sign)
    return lagrangian_dynamics(T, U, Q, QD, QDD)


def rigid() -> SymbolicDynamics:
    """The rigid-body RP arm (link 2's centre of mass at ``l1 + q2 + c2``)."""
    T, U = _energies(l1 + q2 + c2, -1)
    return lagrangian_dynamics(T, U, Q, QD, QDD)


def split(tau: sp.Matrix) -> dict[str, sp.Matrix]:
    """Split ``tau`` into its ``M q̈``, ``C q̇`` (velocity products) and ``G`` parts.

    Args:
        tau: The RP arm's torques, a (2, 1) matrix in the lecture's symbols.
    """
    expanded = sp.expand(tau)
    at_rest = expanded.subs({qd1: 0, qd2: 0, qdd1: 0, qdd2: 0})
    inertial = expanded.subs({qd1: 0, qd2: 0}) - at_rest
    return {"M": sp.expand(inertial), "C": sp.expand(expanded.subs({qdd1: 0, qdd2: 0}) - at_rest), "G": sp.expand(at_rest)}


def in_lecture_symbols(equations):
    """The generated RP arm's equations (``keep_params``) in the lecture's symbols
    ``l1, m1, m2, Iz1, Iz2, c2, g`` instead of the generic ``m_link1, c_link1_x, ...``.

    Args:
        equations: :class:`robodyn.equations.Equations` of ``rp_arm`` with kept parameters.
    """
    by_name = {symbol.name: symbol for symbol in equations.parameters}
    lecture_names = {
        "m_link1": m1,
        "c_link1_x": l1 / 2,
        "I_link1_yy": Iz1,
        "d_joint2_x": l1,
        "m_link2": m2,
        "c_link2_x": c2,
        "I_link2_yy": Iz2,
        "g": g,
    }
    rename = {by_name[name]: value for name, value in lecture_names.items() if name in by_name}
    parameters = {rename[s]: v for s, v in equations.parameters.items() if s in rename and rename[s].is_Symbol}
    return replace(
        equations,
        M=equations.M.subs(rename).applyfunc(sp.factor_terms),
        Cv=equations.Cv.subs(rename).applyfunc(sp.factor_terms),
        G=equations.G.subs(rename).applyfunc(sp.factor_terms),
        C=equations.C.subs(rename).applyfunc(sp.factor_terms),
        parameters=parameters,
        labels={},
    )


def lecture_text() -> str:
    """The lecture's printed RP result, its corrected derivation, and the generated rigid
    arm's equations, entry by entry, with the errata named."""
    corrected = derived().tau
    rigid_tau = rigid().tau
    lines = [
        "The lecture's RP arm: tau = M(q) qdd + C(q, qd) qd + G(q)   (symbols: l1, m1, m2, Iz1, Iz2, g;",
        "the rigid arm's link-2 centre of mass is at l1 + q2 + c2)",
        "",
    ]
    for i in range(2):
        lines += [
            f"tau{i + 1}",
            f"  as printed (slide 34):            {sp.factor_terms(printed()[i])}",
            f"  corrected, lecture's own model:   {sp.factor_terms(sp.expand(corrected[i]))}",
            f"  rigid body (the generated URDF):  {sp.factor_terms(sp.expand(rigid_tau[i]))}",
            "",
        ]
    lines.append("errata:")
    for number, (text, terms) in ERRATA.items():
        lines.append(f"  {number}. {text} (term {', '.join(terms)})")
    return "\n".join(lines) + "\n"
