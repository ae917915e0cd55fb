"""The equations, and a frame's kinematics, as readable text: every name through
:func:`robodyn.common.text.printable`."""

from __future__ import annotations

from robodyn.common.text import printable as terminal_text
from robodyn.equations.model import EquationsData, Kinematics
from robodyn.equations.printing import format_float, to_text_expr


def header(equations: EquationsData, precision: int) -> list[str]:
    """The title, the joints and the kept parameters' values.

    Args:
        equations: The derived equations of motion.
        precision: Significant digits of the parameters' values.
    """
    lines = [
        f"{terminal_text(equations.robot)}: tau = M(q) qdd + C(q, qd) qd + G(q)   "
        f"({equations.form} form, {equations.operation_count()} operations)",
        "joints: "
        + ", ".join(f"{terminal_text(name)} (q = {q})" for name, q in zip(equations.joint_names, equations.q, strict=True)),
        "gravity: (" + ", ".join(format_float(g, precision) for g in equations.gravity) + ") m/s^2",
    ]
    if equations.parameters:
        values = sorted(equations.parameters.items(), key=lambda kv: str(kv[0]))
        lines.append("parameters: " + ", ".join(f"{symbol} = {format_float(value, precision)}" for symbol, value in values))
    return lines


def to_text(equations: EquationsData, *, precision: int = 6) -> str:
    """Assignments (compact form), then every entry of M, C (closed form), C q̇ and G.

    Args:
        equations: The derived equations of motion.
        precision: Significant digits of the numbers printed, 1 to 17.
    """

    def text(expr) -> str:
        return to_text_expr(expr, precision)

    lines = [*header(equations, precision), ""]
    if equations.assignments:
        lines.append("where")
        lines += [f"  {symbol} = {text(expr)}" for symbol, expr in equations.assignments]
        lines.append("")
    n = len(equations.q)
    lines += [f"M[{i + 1},{j + 1}] = {text(equations.M[i, j])}" for i in range(n) for j in range(n)]
    if equations.C is not None:
        lines += [f"C[{i + 1},{j + 1}] = {text(equations.C[i, j])}" for i in range(n) for j in range(n)]
    lines += [f"(C qd)[{i + 1}] = {text(equations.Cv[i])}" for i in range(n)]
    lines += [f"G[{i + 1}] = {text(equations.G[i])}" for i in range(n)]
    return "\n".join(lines) + "\n"


def kinematics_text(kinematics: Kinematics, *, precision: int = 6) -> str:
    """The frame, its joints, then every entry of ``p`` and ``J`` (1-based).

    Args:
        kinematics: The derived frame kinematics (:func:`robodyn.equations.kinematics.derive_kinematics`).
        precision: Significant digits of the numbers printed, 1 to 17.
    """
    k = kinematics
    n = len(k.q)
    lines = [
        f"{terminal_text(k.robot)}: frame {terminal_text(k.frame)}",
        "joints: " + ", ".join(f"{terminal_text(j)} (q = {s})" for j, s in zip(k.joint_names, k.q, strict=True)),
    ]
    lines += [f"p[{i + 1}] = {to_text_expr(e, precision)}" for i, e in enumerate(k.position)]
    lines += [f"J[{i + 1},{j + 1}] = {to_text_expr(k.jacobian[i, j], precision)}" for i in range(6) for j in range(n)]
    return "\n".join(lines) + "\n"
