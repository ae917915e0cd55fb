"""The equations as a LaTeX document (amsmath), or compiled to PDF; a frame's kinematics as a
LaTeX fragment.

Joints are numbered, ``q_1``, ``\\dot q_1``, ``\\ddot q_1``, with a legend table of the
joint names; kept parameters carry their link or joint as an upright subscript
(``m_{\\text{link1}}``); every name passes :func:`robodyn.common.text.latex_text`. Long entries are
broken across lines (at the sums, inside a parenthesised sum where needed) so nothing runs
off the page; ``M`` is a matrix when it fits the line, else printed entry by entry (the
upper triangle: it is symmetric).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import sympy as sp
from sympy.printing.latex import LatexPrinter

from robodyn.common.text import latex_text
from robodyn.equations.model import EquationsData, Kinematics, numeric
from robodyn.equations.printing import format_float
from robodyn.exceptions import MissingToolError, TypesettingError

#: Width of a display line, in characters of typeset math (A4, 2 cm margins, 10 pt).
LINE_WIDTH = 72


class EquationPrinter(LatexPrinter):
    def __init__(self, precision: int, names: dict[sp.Symbol, str]) -> None:
        super().__init__({"symbol_names": names, "mul_symbol": None})
        self.precision = precision

    def _print_Float(self, expr: sp.Float) -> str:
        text = format_float(float(expr), self.precision)
        if "e" in text:
            mantissa, exponent = text.split("e")
            return rf"{mantissa} \cdot 10^{{{int(exponent)}}}"
        return text


#: The start of every LaTeX document robodyn writes (amsmath, A4, breaks between lines allowed).
PREAMBLE = (
    r"\documentclass[10pt]{article}",
    r"\usepackage[T1]{fontenc}",
    r"\usepackage{amsmath}",
    r"\usepackage[a4paper,margin=2cm]{geometry}",
    r"\allowdisplaybreaks",
    r"\begin{document}",
)


def _symbol_names(equations: EquationsData) -> dict[sp.Symbol, str]:
    names = {}
    for index, (q, qd, qdd) in enumerate(zip(equations.q, equations.qd, equations.qdd, strict=True)):
        names[q], names[qd], names[qdd] = rf"q_{{{index + 1}}}", rf"\dot q_{{{index + 1}}}", rf"\ddot q_{{{index + 1}}}"
    for symbol, (kind, owner, component) in equations.labels.items():
        parts = [rf"\text{{{latex_text(owner)}}}"] if owner else []
        parts += [component] if component else []
        names[symbol] = kind + (f"_{{{','.join(parts)}}}" if parts else "")
    for symbol, _ in equations.assignments:
        match = re.fullmatch(r"([A-Za-z]+)([0-9_]*)", symbol.name)
        base, rest = (match.group(1), match.group(2).strip("_").replace("_", ",")) if match else ("x", "")
        names[symbol] = rf"\mathit{{{base}}}_{{{rest}}}" if rest else rf"\mathit{{{base}}}"
    return names


def latex_width(tex: str) -> float:
    """Roughly how many characters wide ``tex`` typesets.

    Args:
        tex: The LaTeX math.
    """
    text = re.sub(r"\\(left|right|bigl|bigr|mathit|text|operatorname)\b", "", tex)
    text = re.sub(r"\\(dot|ddot)\b", "", text)
    text = re.sub(r"\\[A-Za-z]+", "xx", text)
    subscripts = sum(len(m) for m in re.findall(r"[_^]\{([^{}]*)\}", text))
    text = re.sub(r"[{}_^ ]", "", text)
    return len(text) - 0.4 * subscripts


def _signed(printer: EquationPrinter, term: sp.Expr) -> tuple[str, str]:
    if term.could_extract_minus_sign():
        return "-", printer.doprint(-term)
    return "+", printer.doprint(term)


def _lines(printer: EquationPrinter, expr: sp.Expr, width: float) -> list[str]:
    """``expr`` broken into display lines no wider than ``width`` (where it can be)."""
    tex = printer.doprint(expr)
    if latex_width(tex) <= width:
        return [tex]
    if expr.is_Add:
        terms = sorted(expr.args, key=sp.default_sort_key)
        lines: list[str] = []
        for position, term in enumerate(terms):
            sign, body = _signed(printer, term)
            pieces = _lines(printer, -term if sign == "-" else term, width - 4) if latex_width(body) > width else [body]
            prefix = ("" if sign == "+" else "-") if position == 0 else sign + " "
            for k, piece in enumerate(pieces):
                piece = (prefix + piece) if k == 0 else piece
                if lines and k == 0 and latex_width(lines[-1] + piece) <= width:
                    lines[-1] += " " + piece
                else:
                    lines.append(piece)
        return lines
    if expr.is_Mul:
        sums = [f for f in expr.args if f.is_Add]
        if sums:
            inner = max(sums, key=lambda f: len(printer.doprint(f)))
            rest = sp.Mul(*(f for f in expr.args if f is not inner))
            head = "" if rest == 1 else ("-" if rest == -1 else printer.doprint(rest))
            inner_lines = _lines(printer, inner, width - 4)
            return (
                [rf"{head}\bigl({inner_lines[0]}", *inner_lines[1:-1], rf"{inner_lines[-1]}\bigr)"]
                if len(inner_lines) > 1
                else [rf"{head}\left({inner_lines[0]}\right)"]
            )
    return [tex]


def latex_equation(printer: EquationPrinter, left: str, expr: sp.Expr) -> str:
    """One ``align*`` row, continued with ``&\\quad`` lines where long.

    Args:
        printer: The printer (its precision and symbol names).
        left: The LaTeX of the left-hand side.
        expr: The right-hand side.
    """
    lines = _lines(printer, numeric(expr), LINE_WIDTH - latex_width(left))
    rows = [f"{left} &= {lines[0]}"] + [rf"&\quad {line}" for line in lines[1:]]
    return " \\\\\n".join(rows)


def latex_math(equations: EquationsData, *, precision: int = 6) -> str:
    """The equations as ``align*`` environments (for a document or a notebook).

    Args:
        equations: The derived equations of motion.
        precision: Significant digits of the numbers printed.
    """
    printer = EquationPrinter(precision, _symbol_names(equations))
    n = len(equations.q)
    rows = []
    if equations.assignments:
        rows.append([latex_equation(printer, printer.doprint(s), e) for s, e in equations.assignments])
    entries = [[printer.doprint(numeric(equations.M[i, j])) for j in range(n)] for i in range(n)]
    if not equations.assignments and max(sum(latex_width(e) + 3 for e in row) for row in entries) + 8 <= LINE_WIDTH:
        matrix = r" \\ ".join(" & ".join(row) for row in entries)
        rows.append([rf"M(q) &= \begin{{bmatrix}} {matrix} \end{{bmatrix}}"])
    else:  # too wide for a matrix: entry by entry, the upper triangle (M is symmetric)
        rows.append([latex_equation(printer, f"M_{{{i + 1}{j + 1}}}", equations.M[i, j]) for i in range(n) for j in range(i, n)])
    rows.append([latex_equation(printer, rf"(C\dot q)_{{{i + 1}}}", equations.Cv[i]) for i in range(n)])
    rows.append([latex_equation(printer, f"G_{{{i + 1}}}", equations.G[i]) for i in range(n)])
    return "\n".join(r"\begin{align*}" + "\n" + " \\\\\n".join(block) + "\n" + r"\end{align*}" for block in rows)


def to_latex(equations: EquationsData, *, precision: int = 6) -> str:
    """A complete LaTeX document (amsmath): the joints' legend, parameters, equations.

    Args:
        equations: The derived equations of motion.
        precision: Significant digits of the numbers printed.
    """
    names = _symbol_names(equations)
    legend = [
        rf"${names[q]}$ & \texttt{{{latex_text(name)}}} \\" for q, name in zip(equations.q, equations.joint_names, strict=True)
    ]
    body = [
        *PREAMBLE,
        rf"\section*{{Equations of motion of \texttt{{{latex_text(equations.robot)}}}}}",
        r"$\tau = M(q)\,\ddot q + C(q,\dot q)\,\dot q + G(q)$ "
        rf"({latex_text(equations.form)} form, {equations.operation_count()} operations), gravity "
        + "$("
        + ", ".join(format_float(g, precision) for g in equations.gravity)
        + r")\,\mathrm{m/s^2}$.",
        "",
        r"\begin{tabular}{ll}",
        r"coordinate & joint \\ \hline",
        *legend,
        r"\end{tabular}",
    ]
    if equations.parameters:
        values = sorted(equations.parameters.items(), key=lambda kv: str(kv[0]))
        body += [
            "",
            r"\noindent Parameters: " + ", ".join(f"${names[s]} = {format_float(v, precision)}$" for s, v in values) + ".",
        ]
    body += [latex_math(equations, precision=precision), r"\end{document}", ""]
    return "\n".join(body)


def kinematics_latex(kinematics: Kinematics, *, precision: int = 6) -> str:
    """The frame's position and Jacobian as an ``align*`` fragment, with the joints' legend.

    Args:
        kinematics: The derived frame kinematics.
        precision: Significant digits of the numbers printed.
    """
    k = kinematics
    n = len(k.q)
    printer = EquationPrinter(precision, {s: rf"q_{{{i + 1}}}" for i, s in enumerate(k.q)})
    rows = [rf"p_{{{i + 1}}} &= {printer.doprint(numeric(e))}" for i, e in enumerate(k.position)]
    rows += [rf"J_{{{i + 1}{j + 1}}} &= {printer.doprint(numeric(k.jacobian[i, j]))}" for i in range(6) for j in range(n)]
    legend = ", ".join(rf"$q_{{{i + 1}}}$: \texttt{{{latex_text(j)}}}" for i, j in enumerate(k.joint_names))
    return (
        rf"Frame \texttt{{{latex_text(k.frame)}}} ({legend})."
        + "\n\\begin{align*}\n"
        + " \\\\\n".join(rows)
        + "\n\\end{align*}\n"
    )


def tex_engine() -> str | None:
    """The path of ``pdflatex``, or ``None`` when it is not installed."""
    return shutil.which("pdflatex")


def compile_latex(tex: str, folder: Path) -> tuple[Path, str]:
    """Compile a document with pdflatex in ``folder``; the PDF and the log.

    Args:
        tex: The LaTeX document.
        folder: A folder to write ``equations.tex`` and pdflatex's output in.

    Raises:
        MissingToolError: Without pdflatex.
        RobodynError: When TeX reports an error.
    """
    engine = tex_engine()
    if engine is None:
        raise MissingToolError("pdflatex", "PDF output", "install TeX Live (Debian: texlive-latex-base) or use format='latex'")
    source = folder / "equations.tex"
    source.write_text(tex)
    result = subprocess.run(
        [engine, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape", source.name],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=300,
    )
    log = (folder / "equations.log").read_text(errors="replace") if (folder / "equations.log").exists() else result.stdout
    if result.returncode != 0 or not (folder / "equations.pdf").exists():
        first = next((line for line in log.splitlines() if line.startswith("!")), "unknown error")
        raise TypesettingError(first[:200])
    return folder / "equations.pdf", log


def to_pdf(equations: EquationsData, *, precision: int = 6) -> bytes:
    """The document of :func:`to_latex`, compiled with pdflatex.

    Args:
        equations: The derived equations of motion.
        precision: Significant digits of the numbers printed.
    """
    with tempfile.TemporaryDirectory(prefix="robodyn-tex-") as folder:
        pdf, _ = compile_latex(to_latex(equations, precision=precision), Path(folder))
        return pdf.read_bytes()
