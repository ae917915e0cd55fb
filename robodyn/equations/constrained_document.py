"""The derivation of a robot with constraints as one document: steps 1–6 (the open tree's
Lagrangian, :mod:`robodyn.equations.render_derivation`) then steps 7–10 with the
multipliers (:mod:`robodyn.equations.constrained_derivation`), as text, LaTeX or JSON.

``robodyn equations MODEL --derivation`` of a robot with constraints (its file's
``<equality>``, ``--constraints FILE``) prints this instead of the open tree's derivation.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import sympy as sp

from robodyn.common.text import json_text, latex_text, printable
from robodyn.equations.constrained_derivation import ConstrainedDerivation, derive_constrained, readable, to_latex, to_text
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision
from robodyn.equations.render_derivation import render_derivation, to_dict
from robodyn.exceptions import InputError

#: The formats of :func:`constrained_derivation_document`.
FORMATS = ("text", "latex", "json")


def _strings(matrix: sp.Matrix | None) -> list[Any] | None:
    """A matrix as strings sympy reads back (17-digit floats): a column as a list (as the
    steps' ``Cv`` and ``G``), else a list of rows."""
    if matrix is None:
        return None
    values = readable(matrix, 17).tolist()
    if matrix.cols == 1:
        return [sp.sstr(row[0]) for row in values]
    return [[sp.sstr(value) for value in row] for row in values]


def constrained_dict(derivation: ConstrainedDerivation) -> dict[str, Any]:
    """Steps 7–10 as a dictionary: ``constraints`` (descriptions), ``rows`` and
    ``dropped_rows`` (``"<constraint>.<component>"``), ``points``, ``phi``, ``J``,
    ``Jdot_qd``, ``angular_rows`` (a weld's rotation rows: ``phi`` ``sin θ a``, ``J`` the
    relative angular velocity's Jacobian, not ``∂Φ/∂q``), ``relative_rotations`` (each
    weld's ``R₁ R₂ᵀ``), ``tau`` (the torque symbols), ``lambda`` (``None`` when only the
    KKT system states it) and ``kkt``.

    Args:
        derivation: The derivation with multipliers.
    """
    name = [f"{constraint}.{component}" for constraint, component, _ in derivation.labels]
    return {
        "constraints": [str(constraint) for constraint in derivation.constraints],
        "rows": [name[i] for i in derivation.kept],
        "dropped_rows": [name[i] for i in range(len(name)) if i not in derivation.kept],
        "points": [[_strings(first), _strings(second)] for first, second in derivation.points],
        "phi": _strings(derivation.phi),
        "J": _strings(derivation.J),
        "Jdot_qd": _strings(derivation.Jdot_qd),
        "angular_rows": [name[i] for i in derivation.angular],
        "relative_rotations": [_strings(rotation) for rotation in derivation.relative_rotations],
        "tau": [str(symbol) for symbol in derivation.tau],
        "lambda": _strings(derivation.lam),
        "kkt": "[[M, -J^T], [J, 0]] (qdd, lambda) = (tau - Cv - G, -Jdot_qd)",
    }


def constrained_derivation_document(
    source: str | os.PathLike,
    constraints: object,
    *,
    format: str = "text",
    gravity: Sequence[float] | None = None,
    precision: int = DEFAULT_PRECISION,
    keep_params: bool = False,
    lock: dict[str, float] | None = None,
) -> str:
    """Steps 1–10 of a small fixed-base robot under constraints, in one of :data:`FORMATS`.

    Args:
        source: Anything :func:`robodyn.load` takes.
        constraints: As for :func:`~robodyn.equations.constrained_derivation.derive_constrained`
            (a file's ``<equality>`` included by the caller).
        format: One of :data:`FORMATS`.
        gravity: Gravity in the world frame, in [m/s²]; default ``(0, 0, -9.81)``.
        precision: Significant digits of the printed floats (text, LaTeX).
        keep_params: Must be ``False`` (the constrained steps use the file's numbers).
        lock: Must be ``None`` (a locked joint would move the constraints' points).

    Raises:
        InputError: For another format, ``keep_params``, ``lock``, and what
            :func:`~robodyn.equations.constrained_derivation.derive_constrained` refuses.
    """
    check_precision(precision)
    if format not in FORMATS:
        raise InputError("format", f"one of {', '.join(FORMATS)} for a derivation with constraints", repr(format))
    if keep_params:
        raise InputError("keep_params", "False for a derivation with constraints (it uses the file's numbers)", "True")
    if lock:
        raise InputError("lock", "left out for a derivation with constraints (locking moves their points)", "given")
    derivation = derive_constrained(source, constraints, gravity=gravity)
    if format == "json":
        return json_text({**to_dict(derivation.steps), "constrained": constrained_dict(derivation)}, indent=2) + "\n"
    if format == "text":
        opened = str(render_derivation(derivation.steps, "text", precision=precision))
        return opened.rstrip("\n") + "\n\n" + to_text(derivation, precision=precision)
    document = str(render_derivation(derivation.steps, "latex", precision=precision))
    described = [rf"\noindent {latex_text(printable(str(constraint)))}\\" for constraint in derivation.constraints]
    steps = [r"\subsection*{Steps 7--10: the constraints and their multipliers $\lambda$}", *described]
    steps.append(to_latex(derivation, precision=precision))
    head, _, _ = document.rpartition(r"\end{document}")
    return head + "\n".join(steps) + "\n" + r"\end{document}" + "\n"


__all__ = ["FORMATS", "constrained_derivation_document", "constrained_dict"]
