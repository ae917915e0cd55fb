"""The Lagrangian derivation's steps as LaTeX: the math for notebooks (:func:`latex_math`),
a document (:func:`to_latex`) and its PDF (:func:`to_pdf`, with pdflatex).

LaTeX follows the equations' document: joints numbered ``q_1``, ``\\dot q_1``, links
numbered in the order of the derivation, long entries broken across lines. Every name
from the URDF passes :mod:`robodyn.common.text`.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import sympy as sp

from robodyn.common.text import latex_text
from robodyn.equations import lecture
from robodyn.equations.derivation import DerivationSteps
from robodyn.equations.derivation_text import LECTURE_NOTE, STEP_TITLES, errata_at, printed_tau
from robodyn.equations.model import numeric
from robodyn.equations.printing import DEFAULT_PRECISION, format_float
from robodyn.equations.render_latex import LINE_WIDTH, PREAMBLE, EquationPrinter, compile_latex, latex_equation, latex_width

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
    """Every step as ``align*`` environments, titles and errata as text rows (for notebooks).

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
        precision: Significant digits of the printed floats.
    """
    printer = EquationPrinter(precision, _names(steps))
    out = []
    for number, (title, rows) in enumerate(zip(STEP_TITLES, _latex_blocks(steps, printer), strict=True), 1):
        notes = [rf"&\text{{{_prose(f'Erratum {n}: {text}')}}}" for n, text, _ in errata_at(steps, number)]
        out.append(r"\begin{align*}" + "\n" + " \\\\\n".join([rf"&\textbf{{{title}}}", *rows, *notes]) + "\n" + r"\end{align*}")
    return "\n".join(out)


def to_latex(steps: DerivationSteps, *, precision: int = DEFAULT_PRECISION) -> str:
    """A complete LaTeX document (amsmath): legends, then the six steps with their errata.

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
        precision: Significant digits of the printed floats.
    """
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
        body += [r"\noindent " + latex_text(LECTURE_NOTE), ""]
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
    """The document of :func:`to_latex`, compiled with pdflatex.

    Args:
        steps: The derivation (:func:`robodyn.equations.derivation.derive_steps`).
        precision: Significant digits of the printed floats.
    """
    with tempfile.TemporaryDirectory(prefix="robodyn-tex-") as folder:
        pdf, _ = compile_latex(to_latex(steps, precision=precision), Path(folder))
        return pdf.read_bytes()
