"""The Christoffel symbols of the first kind of a closed-form mass matrix.

    Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i),   C_ij = Σ_k Γ_ijk q̇_k,

symmetric in ``j, k``; only the non-zero ones with ``j ≤ k`` are listed, each simplified
like the dynamics. (For the compact form, derive the closed form of a small chain.)
"""

from __future__ import annotations

from typing import Literal

import sympy as sp

from robodyn.common.text import json_text
from robodyn.common.text import printable as terminal_text
from robodyn.equations import simplify
from robodyn.equations.model import EquationsData
from robodyn.equations.printing import check_precision, to_text_expr
from robodyn.exceptions import InputError


def christoffel_symbols(equations: EquationsData) -> dict[tuple[int, int, int], sp.Expr]:
    """Non-zero ``Γ_ijk`` (0-based ``i, j ≤ k``) of a closed form's ``M``.

    Args:
        equations: The derived equations of motion (closed form).

    Raises:
        InputError: For the compact form (its ``M`` is a program, not expressions in ``q``).
    """
    if equations.form != "closed":
        raise InputError("form", "closed for the Christoffel symbols", repr(equations.form))
    M, q = equations.M, equations.q
    n = len(q)
    symbols = {}
    for i in range(n):
        for j in range(n):
            for k in range(j, n):
                gamma = (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j]) - sp.diff(M[j, k], q[i])) / 2
                gamma = simplify.coefficient(gamma, q)
                if gamma != 0:
                    symbols[i, j, k] = gamma
    return symbols


def render_christoffel(equations: EquationsData, format: Literal["text", "json"] = "text", *, precision: int = 6) -> str:
    """The symbols as ``text`` (``Gamma[i,j,k] = ...``, 1-based) or ``json``.

    Args:
        equations: The derived equations of motion (closed form).
        format: ``"text"`` or ``"json"``.
        precision: Significant digits of the numbers printed, 1 to 17.
    """
    check_precision(precision)
    symbols = christoffel_symbols(equations)
    if format == "json":
        data = {
            "robot": equations.robot,
            "joint_names": equations.joint_names,
            "q": [str(s) for s in equations.q],
            "christoffel": [[i + 1, j + 1, k + 1, str(sp.N(e, 17))] for (i, j, k), e in symbols.items()],
        }
        return json_text(data, indent=2) + "\n"
    if format != "text":
        raise InputError("format", "text or json for the Christoffel symbols", repr(format))
    lines = [
        f"{terminal_text(equations.robot)}: Christoffel symbols of the first kind, C_ij = sum_k Gamma[i,j,k] qd_k"
        " (Gamma[i,j,k] = Gamma[i,k,j]; zeros left out)"
    ]
    lines += [f"Gamma[{i + 1},{j + 1},{k + 1}] = {to_text_expr(e, precision)}" for (i, j, k), e in symbols.items()]
    return "\n".join(lines) + "\n"
