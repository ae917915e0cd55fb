"""The symbolic results the renderers receive (the equations of one robot and their size, a
frame's kinematics).

Every symbol in an :class:`EquationsData` (:class:`robodyn.equations.Equations` adds the
notebook display) or a :class:`Kinematics` is a safe identifier (:mod:`robodyn.common.text`);
the raw joint, frame and robot names are kept only for the renderers to escape. Numbers are exact
(rationals, ``π``, ``√2``) until a renderer turns them into floats (:func:`numeric`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from robodyn.common.constants import STANDARD_GRAVITY


@dataclass
class EquationsData:
    """Symbolic equations of motion ``tau = M(q) q̈ + C(q, q̇) q̇ + G(q)`` of one robot.

    Attributes:
        robot: Robot name, as in the URDF (renderers escape it).
        joint_names: Joints in the order of ``q``, as in the URDF.
        form: ``"closed"`` (simplified entries) or ``"compact"`` (assignments first).
        q, qd, qdd: Position, velocity and acceleration symbols (safe identifiers).
        assignments: Intermediate variables ``(symbol, expression)``, in order.
        M, Cv, G: Mass matrix, ``C q̇`` and gravity, in terms of ``q``, ``qd`` and the
            intermediate variables.
        C: The Coriolis matrix (Christoffel form) in closed form, else ``None``.
        parameters: Kept physical parameters and their values (``keep_params``).
        labels: For each kept parameter ``(kind, owner, component)``, e.g.
            ``("m", "link1", "")``, with the owner's raw URDF name.
        gravity: The gravity vector the equations were derived for, in [m/s²].
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
    labels: dict[sp.Symbol, tuple[str, str, str]] = field(default_factory=dict)
    gravity: tuple[float, float, float] = STANDARD_GRAVITY

    def operation_count(self) -> int:
        """See :func:`operation_count`."""
        return operation_count(self)


def numeric(expr: sp.Expr, digits: int = 17) -> sp.Expr:
    """``expr`` with its exact numbers (rationals, ``π``, ``√2``...) as floats of ``digits``
    significant digits; symbols and integers stay.

    Args:
        expr: The expression.
        digits: Significant digits of the floats.
    """
    return expr.evalf(digits) if expr.free_symbols or not expr.is_Integer else expr


def operation_count(equations: EquationsData) -> int:
    """The size of the equations as printed: ``sympy.count_ops`` over every assignment and
    every entry of ``M``, ``C q̇`` and ``G``, numbers as floats (``0.41 q`` is one
    multiplication, not a multiplication and a division).

    Args:
        equations: The equations, as derived.
    """
    expressions = [e for _, e in equations.assignments] + [*equations.M, *equations.Cv, *equations.G]
    return int(sum(sp.count_ops(numeric(e)) for e in expressions))


@dataclass
class Kinematics:
    """A frame's pose and Jacobian as functions of ``q``.

    Attributes:
        robot: Robot name (raw). frame: Frame name (raw).
        joint_names: Joints in the order of ``q`` (raw).
        q: Position symbols (safe identifiers).
        position: World position of the frame's origin, 3×1, in [m].
        rotation: World rotation of the frame, 3×3.
        jacobian: 6×n: linear rows then angular rows (world-aligned).
    """

    robot: str
    frame: str
    joint_names: list[str]
    q: list[sp.Symbol]
    position: sp.Matrix
    rotation: sp.Matrix
    jacobian: sp.Matrix
