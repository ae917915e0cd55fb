"""The Lagrangian derivation's steps as plain text (:func:`to_text`) and JSON data
(:func:`to_dict`), and what every format shares: the steps' titles, the trace of the
matrix form, the lecture's note, errata and printed result.

The LaTeX and PDF forms are in :mod:`robodyn.equations.derivation_latex`; the one call
choosing among them is :func:`robodyn.equations.render_derivation.render_derivation`.
Every name from the URDF passes :mod:`robodyn.common.text`.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from robodyn.common.text import printable as terminal_text
from robodyn.equations import lecture
from robodyn.equations.derivation import LECTURE_ERRATA_STEPS, DerivationSteps
from robodyn.equations.model import numeric
from robodyn.equations.printing import DEFAULT_PRECISION, format_float, to_text_expr

#: The title of every step, in the lecture's order.
STEP_TITLES = (
    "1. Frames and centres of mass in the world",
    "2. Linear and angular velocities",
    "3. Kinetic and potential energy of each link",
    "4. The Lagrangian",
    "5. The Euler-Lagrange equation of each joint",
    "6. The matrix form",
)


#: The step (1..6) of each key of the derivation.
STEP_OF = {"p": 1, "v": 2, "U": 3, "L": 4, "ddt_dL_dqd": 5, "M": 6}


#: How each entry of the matrix form is traced to step 5 (text; LaTeX in :func:`_latex_blocks`).
TRACE = (
    "M[i,j] = d(dL/dqd_i)/dqd_j, the coefficient of qdd_j in d/dt dL/dqd_i",
    "(C qd)[i] = sum_j d(dL/dqd_i)/dq_j qd_j - dT/dq_i, the velocity products of tau_i",
    "G[i] = dU/dq_i, the rest of -dL/dq_i",
    "C[i,j] = sum_k Gamma_ijk qd_k, Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i)/2",
)


LECTURE_NOTE = (
    "The lecture's RP arm (docs/rp-arm.md), in the lecture's order. robodyn's arm turns about -y and moves in the x-z "
    "plane with gravity along -z, where the slides draw the x-y plane with gravity along -y; the symbols (with kept "
    "parameters) are the lecture's m1, m2, l1, Iz1, Iz2, g and c2 = l2/2, link 2's centre of mass being rigid. "
    "Where the printed slides went wrong, the erratum is marked at the step it enters."
)


def errata_at(steps: DerivationSteps, step: int) -> list[tuple[int, str, tuple[str, ...]]]:
    """The lecture's errata entering at ``step`` (1..6): number, text and the terms touched.

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
        step: The step, 1..6.
    """
    if not steps.lecture:
        return []
    return [(n, *lecture.ERRATA[n]) for n, key in LECTURE_ERRATA_STEPS.items() if STEP_OF[key] == step]


def printed_tau(steps: DerivationSteps) -> sp.Matrix:
    """The lecture's result as printed on slide 34, in the derivation's joint symbols.

    Args:
        steps: The lecture arm's derivation.
    """
    joint = {lecture.q1: steps.q[0], lecture.q2: steps.q[1], lecture.qd1: steps.qd[0], lecture.qd2: steps.qd[1]}
    joint.update({lecture.qdd1: steps.qdd[0], lecture.qdd2: steps.qdd[1]})
    return lecture.printed().xreplace(joint)


# ------------------------------------------------------------------------------------------
# JSON
# ------------------------------------------------------------------------------------------
def to_dict(steps: DerivationSteps) -> dict[str, Any]:
    """Every step as strings sympy reads back (17-digit floats), in the equations' naming.

    Keys: ``robot``, ``joint_names``, ``links``, ``link_joints``, ``gravity``, ``q``,
    ``qd``, ``qdd``, ``parameters``; per link ``mass``, ``R``, ``p``, ``Jv``, ``Jw``, ``v``,
    ``omega``, ``T``, ``U``; ``L``; per joint ``dL_dqd``, ``ddt_dL_dqd``, ``dL_dq``, ``tau``;
    ``M``, ``C``, ``Cv``, ``G``; ``trace``; for the lecture's arm ``lecture`` (the printed
    result and the errata with their steps).

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
    """

    def text(expr: sp.Expr) -> str:
        return str(numeric(sp.sympify(expr)))

    def table(matrix: sp.Matrix) -> list:
        return [[text(e) for e in matrix.row(i)] for i in range(matrix.rows)] if matrix.cols > 1 else [text(e) for e in matrix]

    data: dict[str, Any] = {
        "robot": steps.robot,
        "equation": "tau = M(q) qdd + C(q, qd) qd + G(q)",
        "joint_names": list(steps.joint_names),
        "links": [link.link for link in steps.links],
        "link_joints": [link.joint for link in steps.links],
        "gravity": list(steps.gravity),
        "q": [str(s) for s in steps.q],
        "qd": [str(s) for s in steps.qd],
        "qdd": [str(s) for s in steps.qdd],
        "parameters": {str(k): v for k, v in sorted(steps.parameters.items(), key=lambda kv: str(kv[0]))},
    }
    for key in ("mass", "R", "p", "Jv", "Jw", "v", "omega", "T", "U"):
        data[key] = [
            table(value) if isinstance(value := getattr(link, key), sp.MatrixBase) else text(value) for link in steps.links
        ]
    data["L"] = text(steps.L)
    for key in ("dL_dqd", "ddt_dL_dqd", "dL_dq", "tau"):
        data[key] = [text(getattr(joint, key)) for joint in steps.joints]
    data.update(M=table(steps.M), C=table(steps.C), Cv=[text(e) for e in steps.Cv], G=[text(e) for e in steps.G])
    data["trace"] = list(TRACE)
    if steps.lecture:
        data["lecture"] = {
            "printed_tau": [text(e) for e in printed_tau(steps)],
            "errata": [
                {
                    "number": n,
                    "text": t,
                    "terms": list(terms),
                    "step": STEP_OF[LECTURE_ERRATA_STEPS[n]],
                    "key": LECTURE_ERRATA_STEPS[n],
                }
                for n, (t, terms) in sorted(lecture.ERRATA.items())
            ],
        }
    return data


# ------------------------------------------------------------------------------------------
# Text
# ------------------------------------------------------------------------------------------
def _text_header(steps: DerivationSteps, precision: int) -> list[str]:
    lines = [
        f"{terminal_text(steps.robot)}: the Lagrangian derivation, step by step   (tau = M(q) qdd + C(q, qd) qd + G(q))",
        "joints: " + ", ".join(f"{terminal_text(n)} (q = {q})" for n, q in zip(steps.joint_names, steps.q, strict=True)),
        "links: "
        + ", ".join(
            f"{i}. {terminal_text(link.link)} (moved by {terminal_text(link.joint)})" for i, link in enumerate(steps.links, 1)
        ),
        "gravity: (" + ", ".join(format_float(g, precision) for g in steps.gravity) + ") m/s^2",
    ]
    if steps.parameters:
        values = sorted(steps.parameters.items(), key=lambda kv: str(kv[0]))
        lines.append("parameters: " + ", ".join(f"{s} = {format_float(v, precision)}" for s, v in values))
    return lines + ([LECTURE_NOTE] if steps.lecture else [])


def _text_steps(steps: DerivationSteps, precision: int) -> list[list[str]]:
    """The lines of each of the six steps."""

    def t(expr: sp.Expr) -> str:
        return to_text_expr(sp.sympify(expr), precision)

    def vector(matrix: sp.Matrix) -> str:
        return "(" + ", ".join(t(e) for e in matrix) + ")"

    def rows(matrix: sp.Matrix) -> str:
        return "[" + "; ".join(", ".join(t(e) for e in matrix.row(i)) for i in range(matrix.rows)) + "]"

    out: list[list[str]] = [
        [],
        [],
        ["T_i = 1/2 m_i v_i^T v_i + 1/2 omega_i^T R_i I_i R_i^T omega_i,  U_i = -m_i g^T p_i"],
        [],
        [],
        [],
    ]
    for i, link in enumerate(steps.links, 1):
        out[0] += [f"link {i} ({terminal_text(link.link)}):", f"  R_{i} = {rows(link.R)}", f"  p_{i} = {vector(link.p)}"]
        out[1] += [f"  J_v{i} = {rows(link.Jv)}", f"  v_{i} = J_v{i} qd = {vector(link.v)}"]
        out[1] += [f"  J_w{i} = {rows(link.Jw)}", f"  omega_{i} = J_w{i} qd = {vector(link.omega)}"]
        out[2] += [f"  m_{i} = {t(link.mass)},  I_{i} = {rows(link.inertia)}", f"  T_{i} = {t(link.T)}", f"  U_{i} = {t(link.U)}"]
    out[3] = ["L = sum T_i - sum U_i", f"  L = {t(steps.L)}"]
    for joint, q, qd in zip(steps.joints, steps.q, steps.qd, strict=True):
        out[4] += [
            f"joint {terminal_text(joint.joint)}:",
            f"  dL/d{qd} = {t(joint.dL_dqd)}",
            f"  d/dt dL/d{qd} = {t(joint.ddt_dL_dqd)}",
        ]
        out[4] += [f"  dL/d{q} = {t(joint.dL_dq)}", f"  tau_{q.name[2:]} = d/dt dL/d{qd} - dL/d{q} = {t(joint.tau)}"]
    n = len(steps.q)
    out[5] = [f"where {line}" for line in TRACE]
    out[5] += [f"  M[{i + 1},{j + 1}] = {t(steps.M[i, j])}" for i in range(n) for j in range(n)]
    out[5] += [f"  (C qd)[{i + 1}] = {t(steps.Cv[i])}" for i in range(n)]
    out[5] += [f"  G[{i + 1}] = {t(steps.G[i])}" for i in range(n)]
    out[5] += [f"  C[{i + 1},{j + 1}] = {t(steps.C[i, j])}" for i in range(n) for j in range(n)]
    if steps.lecture:
        out[5] += ["as printed on slide 34 (the lecture's symbols):"] + [
            f"  tau_{i + 1} = {t(e)}" for i, e in enumerate(printed_tau(steps))
        ]
    return out


def to_text(steps: DerivationSteps, *, precision: int = DEFAULT_PRECISION) -> str:
    """The derivation as readable text, with the lecture's errata marked where they enter.

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
        precision: Significant digits of the printed floats.
    """
    lines = [*_text_header(steps, precision)]
    for number, (title, body) in enumerate(zip(STEP_TITLES, _text_steps(steps, precision), strict=True), 1):
        lines += ["", f"Step {title}", *body]
        lines += [
            f"  ! erratum {n} of the printed slides (term {', '.join(terms)}): {text}"
            for n, text, terms in errata_at(steps, number)
        ]
    return "\n".join(lines) + "\n"
