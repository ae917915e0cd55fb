"""The equations, and a frame's kinematics, as JSON: names through :func:`robodyn.common.text.json_text`, entries as sympy strings
with 17-digit floats (``sympy.sympify`` reads them back)."""

from __future__ import annotations

from robodyn.common.text import json_text
from robodyn.equations.model import EquationsData, Kinematics, numeric


def to_json(equations: EquationsData) -> str:
    """Symbols, assignments and entries (see the module).

    Args:
        equations: The derived equations of motion.
    """
    n = len(equations.q)

    def text(expr) -> str:
        return str(numeric(expr))

    data = {
        "robot": equations.robot,
        "form": equations.form,
        "equation": "tau = M(q) qdd + C(q, qd) qd + G(q)",
        "joint_names": equations.joint_names,
        "gravity": list(equations.gravity),
        "q": [str(s) for s in equations.q],
        "qd": [str(s) for s in equations.qd],
        "qdd": [str(s) for s in equations.qdd],
        "parameters": {str(k): v for k, v in equations.parameters.items()},
        "assignments": [[str(s), text(e)] for s, e in equations.assignments],
        "M": [[text(equations.M[i, j]) for j in range(n)] for i in range(n)],
        "Cv": [text(e) for e in equations.Cv],
        "G": [text(e) for e in equations.G],
        "C": None if equations.C is None else [[text(equations.C[i, j]) for j in range(n)] for i in range(n)],
        "operations": equations.operation_count(),
    }
    return json_text(data, indent=2) + "\n"


def kinematics_json(kinematics: Kinematics) -> str:
    """The frame's names, ``q``, position, rotation and Jacobian (entries as sympy strings).

    Args:
        kinematics: The derived frame kinematics (:func:`robodyn.equations.kinematics.derive_kinematics`).
    """
    k = kinematics
    n = len(k.q)
    data = {
        "robot": k.robot,
        "frame": k.frame,
        "joint_names": k.joint_names,
        "q": [str(s) for s in k.q],
        "position": [str(numeric(e)) for e in k.position],
        "rotation": [[str(numeric(k.rotation[i, j])) for j in range(3)] for i in range(3)],
        "jacobian": [[str(numeric(k.jacobian[i, j])) for j in range(n)] for i in range(6)],
    }
    return json_text(data, indent=2) + "\n"
