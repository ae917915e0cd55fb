"""URDF in, equations out: closed-form ``tau = M(q) q̈ + C(q, q̇) q̇ + G(q)``, printed or as code.

:func:`derive_equations` asks the independent reference for the equations (never
Pinocchio): small chains (up to three joints, ``form="closed"``) as fully simplified
expressions from the symbolic Lagrangian; larger ones (``form="compact"``) as a short
program of named intermediate variables (:mod:`robodyn.equations.compact`). The
renderers turn them into text, LaTeX (a complete document), JSON, a standalone Python
module (numpy only) or C source with the same functions as :class:`robodyn.Robot`.

Symbols are named after the joints: ``q_<joint>``, ``qd_<joint>`` (velocity),
``qdd_<joint>`` (acceleration). With ``keep_params`` masses, centres of mass, inertias,
joint offsets and ``g`` stay symbols; for the RP arm they are the lecture's ``l1, m1,
m2, Iz1, Iz2, c2, g``.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import sympy as sp

from robodyn import reference
from robodyn.equations.compact import derive_compact
from robodyn.exceptions import InputError
from robodyn.reference.symbolic import derive

FORMATS = ("text", "latex", "json", "python", "c")
#: Largest number of joints derived in fully simplified closed form by default.
CLOSED_FORM_JOINTS = 3


@dataclass
class Equations:
    """Symbolic equations of motion of one robot.

    Attributes:
        robot: Robot name.
        joint_names: Joints in the order of ``q``.
        form: ``"closed"`` (fully simplified entries) or ``"compact"`` (assignments).
        q, qd, qdd: Symbols.
        assignments: Intermediate variables ``(symbol, expression)``, in order.
        M, Cv, G: Mass matrix, ``C q̇`` and gravity, in terms of ``q``, ``qd`` and the
            intermediate variables.
        C: The Coriolis matrix (Christoffel form) when in closed form, else ``None``.
        parameters: Kept physical parameters and their values (``keep_params``).
    """

    robot: str
    joint_names: list[str]
    form: str
    q: list[sp.Symbol]
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    assignments: list[tuple[sp.Symbol, sp.Expr]]
    M: sp.Matrix
    Cv: sp.Matrix
    G: sp.Matrix
    C: sp.Matrix | None = None
    parameters: dict[sp.Symbol, float] = field(default_factory=dict)

    def operation_count(self) -> int:
        """``sympy.count_ops`` over the assignments and the entries of M, C q̇ and G."""
        return int(sum(sp.count_ops(e) for _, e in self.assignments) + sum(sp.count_ops(e) for e in (*self.M, *self.Cv, *self.G)))


def _rp_arm_symbols() -> dict[sp.Symbol, sp.Expr]:
    """The lecture's parameters for the generic symbols of the generated RP arm."""
    from robodyn.equations import lecture

    real = {
        name: sp.Symbol(name, real=True)
        for name in ("m_link1", "c_link1_x", "I_link1_yy", "d_joint2_x", "m_link2", "c_link2_x", "I_link2_yy")
    }
    return {
        real["m_link1"]: lecture.m1,
        real["c_link1_x"]: lecture.l1 / 2,
        real["I_link1_yy"]: lecture.Iz1,
        real["d_joint2_x"]: lecture.l1,
        real["m_link2"]: lecture.m2,
        real["c_link2_x"]: lecture.c2,
        real["I_link2_yy"]: lecture.Iz2,
        sp.Symbol("g", positive=True): lecture.g,
    }


def derive_equations(
    source: str | os.PathLike,
    *,
    form: str = "auto",
    keep_params: bool = False,
    lock: dict[str, float] | None = None,
    floating_base: bool | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> Equations:
    """Derive the equations of motion of a robot symbolically.

    Args:
        source: Anything :func:`robodyn.load` takes.
        form: ``"closed"``, ``"compact"`` or ``"auto"`` (closed up to three joints).
        keep_params: Keep physical parameters as symbols (closed form only).
        lock: Joints to freeze, by name, at positions (e.g. a gripper's fingers).
        floating_base: As for :func:`robodyn.load`; symbolic equations model fixed bases,
            so a robot that would load floating must be asked for with ``False``.
        progress: Called as ``progress(stage, done, total)`` during long derivations.

    Raises:
        InputError: For a floating base, a bad form, or kept parameters in compact form.
    """
    from robodyn.urdf.sources import resolve_source

    if floating_base or (floating_base is None and resolve_source(source).floating_base):
        raise InputError("floating_base", "False: symbolic equations model fixed bases (--fixed-base)", f"a floating {source}")
    model = reference.load(source, lock=lock)
    if form == "auto":
        form = "closed" if model.nv <= CLOSED_FORM_JOINTS or keep_params else "compact"
    if form not in ("closed", "compact"):
        raise InputError("form", "closed, compact or auto", repr(form))
    if form == "compact":
        if keep_params:
            raise InputError("keep_params", "used with the closed form (up to a few joints)", "the compact form")
        compact = derive_compact(model, progress=progress)
        return Equations(
            model.name,
            model.joint_names,
            "compact",
            compact.q,
            compact.qd,
            compact.qdd,
            compact.assignments,
            compact.M,
            compact.Cv,
            compact.G,
        )
    if progress:
        progress("Lagrangian", 0, 1)
    closed = derive(model, keep_params=keep_params)
    parameters = closed.parameters
    matrices = [closed.M, closed.C, closed.G]
    if keep_params and model.name == "rp_arm":
        rename = _rp_arm_symbols()
        matrices = [m.subs(rename).applyfunc(sp.factor_terms) for m in matrices]
        parameters = {rename.get(symbol, symbol): value for symbol, value in parameters.items() if symbol in rename}
    M, C, G = matrices
    used = set().union(*(m.free_symbols for m in matrices))
    parameters = {symbol: value for symbol, value in parameters.items() if symbol in used}
    Cv = (C * sp.Matrix(closed.qd)).applyfunc(lambda e: sp.factor_terms(sp.expand(e)))
    if progress:
        progress("Lagrangian", 1, 1)
    return Equations(model.name, model.joint_names, "closed", closed.q, closed.qd, closed.qdd, [], M, Cv, G, C, parameters)


# --------------------------------------------------------------------------------------
# Rendering
# --------------------------------------------------------------------------------------
def render(equations: Equations, format: str = "text") -> str:
    """The equations in one of :data:`FORMATS`."""
    renderers = {"text": to_text, "latex": to_latex, "json": to_json, "python": to_python, "c": to_c}
    if format not in renderers:
        raise InputError("format", f"one of {', '.join(FORMATS)}", repr(format))
    return renderers[format](equations)


def _header(equations: Equations) -> list[str]:
    lines = [
        f"{equations.robot}: tau = M(q) qdd + C(q, qd) qd + G(q)   ({equations.form} form, {equations.operation_count()} operations)",
        "joints: " + ", ".join(f"{name} (q = {q})" for name, q in zip(equations.joint_names, equations.q, strict=True)),
    ]
    if equations.parameters:
        lines.append(
            "parameters: "
            + ", ".join(
                f"{symbol} = {value:.6g}" for symbol, value in sorted(equations.parameters.items(), key=lambda kv: str(kv[0]))
            )
        )
    return lines


def to_text(equations: Equations) -> str:
    """Readable text: assignments (compact form), then every entry of M, C q̇ (and C), G."""
    lines = [*_header(equations), ""]
    if equations.assignments:
        lines.append("where")
        lines += [f"  {symbol} = {expr}" for symbol, expr in equations.assignments]
        lines.append("")
    n = len(equations.q)
    for i in range(n):
        for j in range(n):
            lines.append(f"M[{i + 1},{j + 1}] = {equations.M[i, j]}")
    if equations.C is not None:
        for i in range(n):
            for j in range(n):
                lines.append(f"C[{i + 1},{j + 1}] = {equations.C[i, j]}")
    lines += [f"(C qd)[{i + 1}] = {equations.Cv[i]}" for i in range(n)]
    lines += [f"G[{i + 1}] = {equations.G[i]}" for i in range(n)]
    return "\n".join(lines) + "\n"


def to_latex(equations: Equations) -> str:
    """A complete LaTeX document (amsmath) with the equations."""

    def tex(expr: sp.Expr) -> str:
        return sp.latex(expr)

    n = len(equations.q)
    title = equations.robot.replace("_", r"\_")
    body = [
        r"\documentclass{article}",
        r"\usepackage{amsmath}",
        r"\usepackage[margin=2cm]{geometry}",
        r"\begin{document}",
        rf"\section*{{Equations of motion of \texttt{{{title}}}}}",
        r"$\tau = M(q)\,\ddot q + C(q,\dot q)\,\dot q + G(q)$, with $q = (" + ", ".join(tex(q) for q in equations.q) + r")$.",
    ]
    if equations.assignments:
        body.append(r"\begin{align*}")
        body += [rf"{tex(symbol)} &= {tex(expr)} \\" for symbol, expr in equations.assignments]
        body.append(r"\end{align*}")
    body.append(r"\begin{align*}")
    for i in range(n):
        for j in range(i, n):
            body.append(rf"M_{{{i + 1}{j + 1}}} &= {tex(equations.M[i, j])} \\")
    for i in range(n):
        body.append(rf"(C\dot q)_{{{i + 1}}} &= {tex(equations.Cv[i])} \\")
    for i in range(n):
        body.append(rf"G_{{{i + 1}}} &= {tex(equations.G[i])} {'' if i == n - 1 else chr(92) * 2}")
    body += [r"\end{align*}", r"\end{document}", ""]
    return "\n".join(body)


def to_json(equations: Equations) -> str:
    """JSON: symbols, assignments and entries as sympy strings."""
    n = len(equations.q)
    data = {
        "robot": equations.robot,
        "form": equations.form,
        "equation": "tau = M(q) qdd + C(q, qd) qd + G(q)",
        "joint_names": equations.joint_names,
        "q": [str(s) for s in equations.q],
        "qd": [str(s) for s in equations.qd],
        "qdd": [str(s) for s in equations.qdd],
        "parameters": {str(k): v for k, v in equations.parameters.items()},
        "assignments": [[str(s), str(e)] for s, e in equations.assignments],
        "M": [[str(equations.M[i, j]) for j in range(n)] for i in range(n)],
        "Cv": [str(e) for e in equations.Cv],
        "G": [str(e) for e in equations.G],
        "C": None if equations.C is None else [[str(equations.C[i, j]) for j in range(n)] for i in range(n)],
        "operations": equations.operation_count(),
    }
    return json.dumps(data, indent=2) + "\n"


def _numbered(equations: Equations) -> tuple[dict[sp.Symbol, sp.Symbol], list[tuple[sp.Symbol, sp.Expr]]]:
    """Replace joint symbols by array accesses and the assignments' names by ``tN``."""
    substitutions = {}
    for index, (q, qd) in enumerate(zip(equations.q, equations.qd, strict=True)):
        substitutions[q] = sp.Symbol(f"q[{index}]")
        substitutions[qd] = sp.Symbol(f"v[{index}]")
    renamed = {symbol: sp.Symbol(f"t{index}") for index, (symbol, _) in enumerate(equations.assignments)}
    substitutions.update(renamed)
    assignments = [(renamed[symbol], expr.xreplace(substitutions)) for symbol, expr in equations.assignments]
    return substitutions, assignments


def to_python(equations: Equations) -> str:
    """A standalone module (numpy only): ``mass_matrix``, ``coriolis_matrix``, ``gravity``,
    ``inverse_dynamics``, with :class:`robodyn.Robot`'s conventions (1-D state, or 2-D
    with one state a row)."""
    if equations.parameters:
        raise InputError("keep_params", "not used with code output (code needs numbers)", "kept parameters")
    from sympy.printing.numpy import NumPyPrinter

    substitutions, assignments = _numbered(equations)
    printer = NumPyPrinter({"fully_qualified_modules": True})
    n = len(equations.q)

    def code(expr: sp.Expr) -> str:
        text = printer.doprint(expr.xreplace(substitutions))
        return text.replace("numpy.", "np.")

    zero = "np.zeros_like(q[0])"
    lines = [
        f'"""Equations of motion of {equations.robot}, generated by robodyn from its URDF ({equations.form} form).',
        "",
        f"Joints, in the order of q: {', '.join(equations.joint_names)}.",
        "Every function takes one state as 1-D arrays or a trajectory as 2-D arrays (one state a",
        "row), like robodyn.Robot. SI units. Needs numpy only.",
        '"""',
        "",
        "import numpy as np",
        "",
        f"JOINT_NAMES = {equations.joint_names!r}",
        "",
        "",
        "def _terms(q, v):",
        '    """M, C v and G for states stacked along the first axis of q.T (columns)."""',
    ]
    lines += [f"    {symbol} = {code(expr)}" for symbol, expr in assignments]
    entries = ", ".join("[" + ", ".join(code(equations.M[i, j]) + f" + {zero}" for j in range(n)) + "]" for i in range(n))
    lines.append(f"    M = np.array([{entries}], dtype=float)")
    lines.append("    Cv = np.array([" + ", ".join(code(e) + f" + {zero}" for e in equations.Cv) + "], dtype=float)")
    lines.append("    G = np.array([" + ", ".join(code(e) + f" + {zero}" for e in equations.G) + "], dtype=float)")
    lines.append("    return M, Cv, G")
    lines += [
        "",
        "",
        "def _columns(x):",
        "    x = np.asarray(x, dtype=float)",
        f"    if x.shape[-1] != {n}:",
        f'        raise ValueError(f"expected {n} values a state, got {{x.shape[-1]}}")',
        "    return x.T, x.ndim == 1",
        "",
        "",
        "def mass_matrix(q):",
        '    """M(q): shape (n, n) or (N, n, n)."""',
        "    qc, single = _columns(q)",
        "    M = _terms(qc, np.zeros_like(qc))[0]",
        "    return M if single else np.moveaxis(M, -1, 0)",
        "",
        "",
        "def gravity(q):",
        '    """G(q): shape (n,) or (N, n)."""',
        "    qc, single = _columns(q)",
        "    G = _terms(qc, np.zeros_like(qc))[2]",
        "    return G if single else G.T",
        "",
        "",
        "def coriolis_forces(q, v):",
        '    """C(q, v) v: shape (n,) or (N, n)."""',
        "    qc, single = _columns(q)",
        "    vc, _ = _columns(v)",
        "    Cv = _terms(qc, vc)[1]",
        "    return Cv if single else Cv.T",
        "",
        "",
        "def coriolis_matrix(q, v):",
        '    """C(q, v), Christoffel form: shape (n, n) or (N, n, n).',
        "",
        "    C v is quadratic in v, C_ij = ½ ∂(C v)_i/∂v_j, so column j is exactly",
        "    ((C v)(v + e_j) − (C v)(v − e_j)) / 4.",
        '    """',
        "    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)",
        f"    eye = np.eye({n})",
        "    columns = [(coriolis_forces(q, v + e) - coriolis_forces(q, v - e)) / 4 for e in eye]",
        "    return np.stack(columns, axis=-1)",
        "",
        "",
        "def inverse_dynamics(q, v, a):",
        '    """tau = M(q) a + C(q, v) v + G(q): shape (n,) or (N, n)."""',
        "    qc, single = _columns(q)",
        "    vc, _ = _columns(v)",
        "    ac, _ = _columns(a)",
        "    M, Cv, G = _terms(qc, vc)",
        "    tau = np.einsum('ij...,j...->i...', M, ac) + Cv + G",
        "    return tau if single else tau.T",
        "",
    ]
    return "\n".join(lines)


def to_c(equations: Equations) -> str:
    """C99 source with ``mass_matrix``, ``coriolis_forces``, ``coriolis_matrix``,
    ``gravity`` and ``inverse_dynamics`` (one state; arrays of doubles, row-major)."""
    if equations.parameters:
        raise InputError("keep_params", "not used with code output (code needs numbers)", "kept parameters")
    substitutions, assignments = _numbered(equations)
    n = len(equations.q)
    name = "".join(ch if ch.isalnum() else "_" for ch in equations.robot)

    def code(expr: sp.Expr) -> str:
        return sp.ccode(expr.xreplace(substitutions), standard="C99")

    lines = [
        f"/* Equations of motion of {equations.robot}, generated by robodyn ({equations.form} form).",
        f"   Joints: {', '.join(equations.joint_names)}. SI units; M and C row-major. */",
        "#include <math.h>",
        "",
        f"#define {name.upper()}_DOF {n}",
        "",
        "static void terms(const double *q, const double *v, double *M, double *Cv, double *G) {",
    ]
    lines += [f"    const double {symbol} = {code(expr)};" for symbol, expr in assignments]
    for i in range(n):
        for j in range(n):
            lines.append(f"    if (M) M[{i * n + j}] = {code(equations.M[i, j])};")
    lines += [f"    if (Cv) Cv[{i}] = {code(e)};" for i, e in enumerate(equations.Cv)]
    lines += [f"    if (G) G[{i}] = {code(e)};" for i, e in enumerate(equations.G)]
    lines += [
        "}",
        "",
        f"static const double ZERO[{n}] = {{0}};",
        "",
        "void mass_matrix(const double *q, double *M) { terms(q, ZERO, M, 0, 0); }",
        "void gravity(const double *q, double *G) { terms(q, ZERO, 0, 0, G); }",
        "void coriolis_forces(const double *q, const double *v, double *Cv) { terms(q, v, 0, Cv, 0); }",
        "",
        "/* C_ij = 1/2 d(Cv)_i/dv_j, exact for the quadratic C v: column j = (Cv(v+e_j) - Cv(v-e_j)) / 4. */",
        "void coriolis_matrix(const double *q, const double *v, double *C) {",
        f"    double w[{n}], plus[{n}], minus[{n}];",
        f"    for (int j = 0; j < {n}; ++j) {{",
        f"        for (int k = 0; k < {n}; ++k) w[k] = v[k];",
        "        w[j] = v[j] + 1.0; coriolis_forces(q, w, plus);",
        "        w[j] = v[j] - 1.0; coriolis_forces(q, w, minus);",
        f"        for (int i = 0; i < {n}; ++i) C[i * {n} + j] = (plus[i] - minus[i]) / 4.0;",
        "    }",
        "}",
        "",
        "void inverse_dynamics(const double *q, const double *v, const double *a, double *tau) {",
        f"    double M[{n * n}], Cv[{n}], G[{n}];",
        "    terms(q, v, M, Cv, G);",
        f"    for (int i = 0; i < {n}; ++i) {{",
        "        tau[i] = Cv[i] + G[i];",
        f"        for (int j = 0; j < {n}; ++j) tau[i] += M[i * {n} + j] * a[j];",
        "    }",
        "}",
        "",
    ]
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# The lecture, side by side
# --------------------------------------------------------------------------------------
def lecture_text() -> str:
    """The lecture's printed RP result, its corrected derivation, and the generated rigid
    arm's equations, entry by entry, with the errata named."""
    from robodyn.equations import lecture

    printed = lecture.printed()
    corrected = lecture.derived().tau
    rigid = lecture.rigid().tau
    lines = [
        "The lecture's RP arm: tau = M(q) qdd + C(q, qd) qd + G(q)   (symbols: l1, m1, m2, Iz1, Iz2, g;",
        "the rigid arm's link-2 centre of mass is at l1 + q2 + c2)",
        "",
    ]
    for i in range(2):
        lines += [
            f"tau{i + 1}",
            f"  as printed (slide 34):            {sp.factor_terms(printed[i])}",
            f"  corrected, lecture's own model:   {sp.factor_terms(sp.expand(corrected[i]))}",
            f"  rigid body (the generated URDF):  {sp.factor_terms(sp.expand(rigid[i]))}",
            "",
        ]
    lines.append("errata:")
    for number, (text, terms) in lecture.ERRATA.items():
        lines.append(f"  {number}. {text} (term {', '.join(terms)})")
    return "\n".join(lines) + "\n"
