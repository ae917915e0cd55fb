"""The Lagrangian derivation of :mod:`robodyn.equations.derivation` as text, LaTeX, PDF or JSON.

:func:`derivation` gives a :class:`Derivation` (the steps, ``to_dict()`` and, in notebooks,
``_repr_latex_``); :func:`derivation_document` is the one call behind
``robodyn equations MODEL --derivation``. Every name from the URDF passes
:mod:`robodyn.common.text`; numbers are exact until printed, then floats of
``precision`` significant digits (17 in JSON, as the equations' JSON). LaTeX follows the
equations' document: joints numbered ``q_1``, ``\\dot q_1``, links numbered in the order
of the derivation, long entries broken across lines.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any, Literal

import sympy as sp

from robodyn.common.text import json_text, latex_text
from robodyn.common.text import printable as terminal_text
from robodyn.equations import lecture
from robodyn.equations.derivation import LECTURE_ERRATA_STEPS, DerivationSteps, derive_steps
from robodyn.equations.model import numeric
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision, format_float, to_text_expr
from robodyn.equations.render_latex import LINE_WIDTH, PREAMBLE, EquationPrinter, compile_latex, latex_equation, latex_width
from robodyn.exceptions import InputError

DerivationFormat = Literal["text", "latex", "pdf", "json"]
#: The formats of :func:`render_derivation`.
DERIVATION_FORMATS = ("text", "latex", "pdf", "json")
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
_LECTURE_NOTE = (
    "The lecture's RP arm (docs/rp-arm.md), in the lecture's order. robodyn's arm turns about -y and moves in the x-z "
    "plane with gravity along -z, where the slides draw the x-y plane with gravity along -y; the symbols (with kept "
    "parameters) are the lecture's m1, m2, l1, Iz1, Iz2, g and c2 = l2/2, link 2's centre of mass being rigid. "
    "Where the printed slides went wrong, the erratum is marked at the step it enters."
)
_LECTURE_NAMES = {
    lecture.m1: "m_{1}",
    lecture.m2: "m_{2}",
    lecture.l1: "l_{1}",
    lecture.c2: "c_{2}",
    lecture.Iz1: "I_{z1}",
    lecture.Iz2: "I_{z2}",
    lecture.g: "g",
}
_PROSE = {"ḡ": r"$\bar g$", "·": r"$\cdot$", "−": "$-$"}


class Derivation(DerivationSteps):
    """The steps of :class:`DerivationSteps`, as a dictionary and in notebooks as LaTeX."""

    def to_dict(self) -> dict[str, Any]:
        """Every step (see :func:`to_dict`)."""
        return to_dict(self)

    def _repr_latex_(self) -> str:
        """The derivation for notebooks (Jupyter renders this with MathJax)."""
        return latex_math(self)


def derivation(
    source: str | os.PathLike,
    *,
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
) -> Derivation:
    """The Lagrangian derivation of a small robot (arguments as :func:`derive_steps`)."""
    steps = derive_steps(source, keep_params=keep_params, gravity=gravity, lock=lock)
    return Derivation(**{f.name: getattr(steps, f.name) for f in fields(steps)})


def derivation_document(
    source: str | os.PathLike,
    *,
    format: DerivationFormat = "text",
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
    precision: int = DEFAULT_PRECISION,
) -> str | bytes:
    """The derivation of a robot in one of :data:`DERIVATION_FORMATS` (``"pdf"`` gives bytes).

    Raises:
        InputError: For an unknown format or precision, or a robot too large.
        MissingToolError: For ``"pdf"`` without pdflatex.
    """
    _check(format, precision)
    return render_derivation(derivation(source, keep_params=keep_params, gravity=gravity, lock=lock), format, precision=precision)


def _check(format: str, precision: int) -> None:
    check_precision(precision)
    if format not in DERIVATION_FORMATS:
        raise InputError("format", f"one of {', '.join(DERIVATION_FORMATS)} for a derivation", repr(format))


def render_derivation(
    steps: DerivationSteps, format: DerivationFormat = "text", *, precision: int = DEFAULT_PRECISION
) -> str | bytes:
    """``steps`` as text, a LaTeX document, a PDF (bytes) or JSON."""
    _check(format, precision)
    if format == "text":
        return to_text(steps, precision=precision)
    if format == "latex":
        return to_latex(steps, precision=precision)
    if format == "pdf":
        return to_pdf(steps, precision=precision)
    return json_text(to_dict(steps), indent=2) + "\n"


def errata_at(steps: DerivationSteps, step: int) -> list[tuple[int, str, tuple[str, ...]]]:
    """The lecture's errata entering at ``step`` (1..6): number, text and the terms touched."""
    if not steps.lecture:
        return []
    return [(n, *lecture.ERRATA[n]) for n, key in LECTURE_ERRATA_STEPS.items() if STEP_OF[key] == step]


def printed_tau(steps: DerivationSteps) -> sp.Matrix:
    """The lecture's result as printed on slide 34, in the derivation's joint symbols."""
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
    return lines + ([_LECTURE_NOTE] if steps.lecture else [])


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
    """The derivation as readable text, with the lecture's errata marked where they enter."""
    lines = [*_text_header(steps, precision)]
    for number, (title, body) in enumerate(zip(STEP_TITLES, _text_steps(steps, precision), strict=True), 1):
        lines += ["", f"Step {title}", *body]
        lines += [
            f"  ! erratum {n} of the printed slides (term {', '.join(terms)}): {text}"
            for n, text, terms in errata_at(steps, number)
        ]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------
# LaTeX
# ------------------------------------------------------------------------------------------
def _names(steps: DerivationSteps) -> dict[sp.Symbol, str]:
    names: dict[sp.Symbol, str] = dict(_LECTURE_NAMES)
    for index, (q, qd, qdd) in enumerate(zip(steps.q, steps.qd, steps.qdd, strict=True), 1):
        names[q], names[qd], names[qdd] = rf"q_{{{index}}}", rf"\dot q_{{{index}}}", rf"\ddot q_{{{index}}}"
    for symbol, (kind, owner, component) in steps.labels.items():
        parts = [rf"\text{{{latex_text(owner)}}}"] if owner else []
        parts += [component] if component else []
        names[symbol] = kind + (f"_{{{','.join(parts)}}}" if parts else "")
    return names


def _column(printer: EquationPrinter, symbol: str, matrix: sp.Matrix, tail: str = "") -> list[str]:
    """``symbol tail = matrix`` as one ``bmatrix`` row when it fits the line, else entry by
    entry as ``(symbol)_{x}`` (vectors) or ``(symbol)_{x1}`` (matrices)."""
    entries = [[printer.doprint(numeric(sp.sympify(e))) for e in matrix.row(i)] for i in range(matrix.rows)]
    left = symbol + tail
    widest = max(sum(latex_width(e) + 3 for e in row) for row in entries)
    if widest + latex_width(left) + 8 <= LINE_WIDTH:
        body = r" \\ ".join(" & ".join(row) for row in entries)
        return [rf"{left} &= \begin{{bmatrix}} {body} \end{{bmatrix}}"]
    axes = "xyz" if matrix.rows == 3 else [str(k + 1) for k in range(matrix.rows)]
    if matrix.cols == 1:
        return [latex_equation(printer, rf"({symbol})_{{{axes[r]}}}", matrix[r]) for r in range(matrix.rows)]
    cells = [(r, c) for r in range(matrix.rows) for c in range(matrix.cols)]
    return [latex_equation(printer, rf"({symbol})_{{{axes[r]}{c + 1}}}", matrix[r, c]) for r, c in cells]


def _latex_blocks(steps: DerivationSteps, printer: EquationPrinter) -> list[list[str]]:
    """The ``align*`` rows of each of the six steps."""
    blocks: list[list[str]] = [[], [], [], [], [], []]
    for i, link in enumerate(steps.links, 1):
        blocks[0] += _column(printer, f"R_{{{i}}}", link.R) + _column(printer, f"p_{{{i}}}", link.p)
        blocks[1] += _column(printer, rf"J_{{v,{i}}}", link.Jv) + _column(printer, f"v_{{{i}}}", link.v, rf" = J_{{v,{i}}}\dot q")
        blocks[1] += _column(printer, rf"\omega_{{{i}}}", link.omega, rf" = J_{{\omega,{i}}}\dot q")
        blocks[2] += [latex_equation(printer, f"m_{{{i}}}", link.mass), latex_equation(printer, f"T_{{{i}}}", link.T)]
        blocks[2] += [latex_equation(printer, f"U_{{{i}}}", link.U)]
    blocks[3] = [latex_equation(printer, r"L = \textstyle\sum_i T_i - \sum_i U_i", steps.L)]
    for i, joint in enumerate(steps.joints, 1):
        blocks[4] += [
            latex_equation(printer, rf"\frac{{\partial L}}{{\partial \dot q_{{{i}}}}}", joint.dL_dqd),
            latex_equation(printer, rf"\frac{{d}}{{dt}}\frac{{\partial L}}{{\partial \dot q_{{{i}}}}}", joint.ddt_dL_dqd),
            latex_equation(printer, rf"\frac{{\partial L}}{{\partial q_{{{i}}}}}", joint.dL_dq),
            latex_equation(printer, rf"\tau_{{{i}}}", joint.tau),
        ]
    n = len(steps.q)
    trace = [
        r"M_{ij} &= \frac{\partial^2 L}{\partial \dot q_i\,\partial \dot q_j} \text{ (the coefficient of $\ddot q_j$ in $\tfrac{d}{dt}\tfrac{\partial L}{\partial \dot q_i}$)}",
        r"(C\dot q)_i &= \textstyle\sum_j \frac{\partial^2 L}{\partial \dot q_i\,\partial q_j}\dot q_j - \frac{\partial T}{\partial q_i},"
        r"\quad G_i = \frac{\partial U}{\partial q_i}",
    ]
    blocks[5] = trace + [latex_equation(printer, f"M_{{{i + 1}{j + 1}}}", steps.M[i, j]) for i in range(n) for j in range(i, n)]
    blocks[5] += [latex_equation(printer, rf"(C\dot q)_{{{i + 1}}}", steps.Cv[i]) for i in range(n)]
    blocks[5] += [latex_equation(printer, f"G_{{{i + 1}}}", steps.G[i]) for i in range(n)]
    if steps.lecture:
        blocks[5] += [
            latex_equation(printer, rf"\tau_{{{i + 1}}}^{{\text{{printed}}}}", e) for i, e in enumerate(printed_tau(steps))
        ]
    return blocks


def _prose(text: str) -> str:
    """Plain text for LaTeX, the errata's few symbols as math."""
    return "".join(_PROSE.get(ch) or latex_text(ch) for ch in text)


def _errata_tex(steps: DerivationSteps, step: int) -> list[str]:
    return [
        rf"\noindent\textbf{{Erratum {n} of the printed slides}} (term {', '.join(terms)}): {_prose(text)}."
        for n, text, terms in errata_at(steps, step)
    ]


def latex_math(steps: DerivationSteps, *, precision: int = DEFAULT_PRECISION) -> str:
    """Every step as ``align*`` environments, titles and errata as text rows (for notebooks)."""
    printer = EquationPrinter(precision, _names(steps))
    out = []
    for number, (title, rows) in enumerate(zip(STEP_TITLES, _latex_blocks(steps, printer), strict=True), 1):
        notes = [rf"&\text{{{_prose(f'Erratum {n}: {text}')}}}" for n, text, _ in errata_at(steps, number)]
        out.append(r"\begin{align*}" + "\n" + " \\\\\n".join([rf"&\textbf{{{title}}}", *rows, *notes]) + "\n" + r"\end{align*}")
    return "\n".join(out)


def to_latex(steps: DerivationSteps, *, precision: int = DEFAULT_PRECISION) -> str:
    """A complete LaTeX document (amsmath): legends, then the six steps with their errata."""
    printer = EquationPrinter(precision, _names(steps))
    names = _names(steps)
    body = [
        *PREAMBLE,
        rf"\section*{{The Lagrangian of \texttt{{{latex_text(steps.robot)}}}, step by step}}",
        r"$\tau = \frac{d}{dt}\frac{\partial L}{\partial \dot q} - \frac{\partial L}{\partial q} = M(q)\,\ddot q + C(q,\dot q)\,\dot q + G(q)$, "
        r"gravity $g = (" + ", ".join(format_float(g, precision) for g in steps.gravity) + r")\,\mathrm{m/s^2}$.",
        "",
        r"\begin{tabular}{ll}",
        r"coordinate & joint \\ \hline",
        *[rf"${names[q]}$ & \texttt{{{latex_text(n)}}} \\" for q, n in zip(steps.q, steps.joint_names, strict=True)],
        r"\end{tabular}\qquad",
        r"\begin{tabular}{lll}",
        r"link & name & moved by \\ \hline",
        *[
            rf"{i} & \texttt{{{latex_text(link.link)}}} & \texttt{{{latex_text(link.joint)}}} \\"
            for i, link in enumerate(steps.links, 1)
        ],
        r"\end{tabular}",
        "",
    ]
    if steps.parameters:
        values = sorted(steps.parameters.items(), key=lambda kv: str(kv[0]))
        body += [
            r"\noindent Parameters: " + ", ".join(f"${names[s]} = {format_float(v, precision)}$" for s, v in values) + ".",
            "",
        ]
    if steps.lecture:
        body += [r"\noindent " + latex_text(_LECTURE_NOTE), ""]
    for number, (title, rows) in enumerate(zip(STEP_TITLES, _latex_blocks(steps, printer), strict=True), 1):
        body += [
            rf"\subsection*{{{title}}}",
            r"\begin{align*}",
            " \\\\\n".join(rows),
            r"\end{align*}",
            *_errata_tex(steps, number),
        ]
    return "\n".join([*body, r"\end{document}", ""])


def to_pdf(steps: DerivationSteps, *, precision: int = DEFAULT_PRECISION) -> bytes:
    """The document of :func:`to_latex`, compiled with pdflatex."""
    with tempfile.TemporaryDirectory(prefix="robodyn-tex-") as folder:
        pdf, _ = compile_latex(to_latex(steps, precision=precision), Path(folder))
        return pdf.read_bytes()
