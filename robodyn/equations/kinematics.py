"""Forward kinematics of one frame and its Jacobian, in closed form and as code.

The frame is a link (or a moving joint's child link) of the URDF; fixed joints between it
and the body that carries it are folded in. Its world position ``p(q)``, rotation
``R(q)`` and the Jacobian ``J(q)`` (rows 0-2: ``∂p/∂q``; rows 3-5: the angular velocity's
axes, Pinocchio's ``LOCAL_WORLD_ALIGNED`` convention, as :meth:`robodyn.Robot.frame_jacobian`)
come from the reference's symbolic kinematics with exact constants, each entry simplified
like the dynamics (:mod:`robodyn.equations.simplify`). No Pinocchio here.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn import reference
from robodyn.common.rotations import rpy_matrix
from robodyn.common.text import comment_text, identifier, json_text, latex_text
from robodyn.common.text import printable as terminal_text
from robodyn.equations import simplify
from robodyn.equations.model import numeric
from robodyn.equations.printing import check_precision, to_text_expr
from robodyn.exceptions import FrameError, InputError
from robodyn.reference.symbolic import Parameters, body_coordinates, body_poses, exact_matrix


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


def derive_kinematics(
    source: str | os.PathLike,
    frame: str,
    *,
    lock: dict[str, float] | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> Kinematics:
    """Closed-form forward kinematics and Jacobian of ``frame`` (a link name).

    Args:
        source: Anything :func:`robodyn.load` takes.
        frame: A link of the robot.
        lock: Joints to freeze, by name, at positions.
        progress: Called as ``progress(stage, done, total)`` while entries are simplified.

    Raises:
        FrameError: For a name that is not a link of the robot.
    """
    model = reference.load(source, lock=lock)
    spec = model.spec
    if frame not in spec.links:
        raise FrameError(frame, model.name)
    by_child = {joint.child: joint for joint in spec.joints.values()}
    carried = {body.link: index for index, body in enumerate(model.tree.bodies)}
    transform = np.eye(4)
    link = frame
    while link not in carried and link in by_child:
        joint = by_child[link]
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = rpy_matrix(joint.origin_rpy), joint.origin_xyz
        transform = step @ transform
        link = joint.parent
    taken: set[str] = set()
    q = [sp.Symbol(identifier(name, taken, prefix="q_"), real=True) for name in model.joint_names]
    qd = [sp.Symbol(f"_v{i}", real=True) for i in range(len(q))]
    theta, _ = body_coordinates(model, q, qd)
    rotations, positions, axes = body_poses(model, theta, Parameters(False))
    fixed_rotation, fixed_offset = exact_matrix(transform[:3, :3], 1e-8), exact_matrix(transform[:3, 3:], 0.0)
    n = len(q)
    if link in carried:
        b = carried[link]
        rotation, position = rotations[b] * fixed_rotation, positions[b] + rotations[b] * fixed_offset
        angular = sp.zeros(3, n)
        selection = exact_matrix(model.tree.selection, 0.0)
        for ancestor, body in enumerate(model.tree.bodies):
            if model.tree.ancestors[b, ancestor] and body.revolute:
                angular += axes[ancestor] * selection[ancestor, :]
    else:  # a frame on the fixed base
        rotation, position, angular = fixed_rotation, fixed_offset, sp.zeros(3, n)
    total, done = 3 + 9 + 6 * n, [0]

    def tidy(expr: sp.Expr) -> sp.Expr:
        if progress:
            progress("simplification", done[0], total)
        done[0] += 1
        return simplify.coefficient(expr, q)

    position = position.applyfunc(tidy)
    rotation = rotation.applyfunc(tidy)
    jacobian = position.jacobian(q).applyfunc(tidy).col_join(angular.applyfunc(tidy))
    if progress:
        progress("simplification", total, total)
    return Kinematics(model.name, frame, list(model.joint_names), q, position, rotation, jacobian)


def render_kinematics(kinematics: Kinematics, format: str = "text", *, precision: int = 6) -> str:
    """The frame's position and Jacobian as ``text``, ``latex`` (a fragment), ``json``,
    ``python`` (a module with ``frame_position(q)`` and ``frame_jacobian(q)``) or ``c``
    (the same two functions, one state, arrays of doubles)."""
    check_precision(precision)
    k = kinematics
    n = len(k.q)
    if format == "text":
        lines = [
            f"{terminal_text(k.robot)}: frame {terminal_text(k.frame)}",
            "joints: " + ", ".join(f"{terminal_text(j)} (q = {s})" for j, s in zip(k.joint_names, k.q, strict=True)),
        ]
        lines += [f"p[{i + 1}] = {to_text_expr(e, precision)}" for i, e in enumerate(k.position)]
        lines += [f"J[{i + 1},{j + 1}] = {to_text_expr(k.jacobian[i, j], precision)}" for i in range(6) for j in range(n)]
        return "\n".join(lines) + "\n"
    if format == "json":
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
    if format == "latex":
        from robodyn.equations.render_latex import _Printer

        names = {s: rf"q_{{{i + 1}}}" for i, s in enumerate(k.q)}
        printer = _Printer(precision, names)
        rows = [rf"p_{{{i + 1}}} &= {printer.doprint(numeric(e))}" for i, e in enumerate(k.position)]
        rows += [rf"J_{{{i + 1}{j + 1}}} &= {printer.doprint(numeric(k.jacobian[i, j]))}" for i in range(6) for j in range(n)]
        legend = ", ".join(rf"$q_{{{i + 1}}}$: \texttt{{{latex_text(j)}}}" for i, j in enumerate(k.joint_names))
        return (
            rf"Frame \texttt{{{latex_text(k.frame)}}} ({legend})."
            + "\n\\begin{align*}\n"
            + " \\\\\n".join(rows)
            + "\n\\end{align*}\n"
        )
    if format == "python":
        from sympy.printing.numpy import NumPyPrinter

        printer = NumPyPrinter({"fully_qualified_modules": True})
        to_array = {s: sp.Symbol(f"q[{i}]") for i, s in enumerate(k.q)}

        def code(e: sp.Expr) -> str:
            return printer.doprint(numeric(e.xreplace(to_array))).replace("numpy.", "np.") + " + z"

        position = ", ".join(code(e) for e in k.position)
        jacobian = ", ".join("[" + ", ".join(code(k.jacobian[i, j]) for j in range(n)) + "]" for i in range(6))
        return "\n".join(
            [
                f'"""Forward kinematics of frame {comment_text(k.frame)} of {comment_text(k.robot)}, generated by robodyn.',
                "",
                "q: shape (n,) or (N, n). frame_position: (3,) or (N, 3) in [m]; frame_jacobian: (6, n) or",
                '(N, 6, n), linear rows then angular rows, world-aligned."""',
                "",
                "import numpy as np",
                "",
                f"JOINT_NAMES = [{', '.join(ascii(j) for j in k.joint_names)}]",
                "",
                "",
                "def frame_position(q):",
                "    q = np.asarray(q, dtype=float).T",
                "    z = np.zeros_like(q[0])",
                f"    p = np.array([{position}], dtype=float)",
                "    return p.T",
                "",
                "",
                "def frame_jacobian(q):",
                "    q = np.asarray(q, dtype=float).T",
                "    z = np.zeros_like(q[0])",
                f"    J = np.array([{jacobian}], dtype=float)",
                "    return J if J.ndim == 2 else np.moveaxis(J, -1, 0)",
                "",
            ]
        )
    if format == "c":
        to_array = {s: sp.Symbol(f"q[{i}]") for i, s in enumerate(k.q)}

        def c_code(e: sp.Expr) -> str:
            return sp.ccode(numeric(e.xreplace(to_array)), standard="C99")

        lines = [
            f"/* Forward kinematics of frame {comment_text(k.frame)} of {comment_text(k.robot)}, generated by robodyn.",
            f"   Joints: {', '.join(comment_text(j) for j in k.joint_names)}. p in [m]; J row-major 6 x {n},",
            "   linear rows then angular rows, world-aligned. */",
            "#include <math.h>",
            "",
            "void frame_position(const double *q, double *p) {",
            *(f"    p[{i}] = {c_code(e)};" for i, e in enumerate(k.position)),
            "}",
            "",
            "void frame_jacobian(const double *q, double *J) {",
            *(f"    J[{i * n + j}] = {c_code(k.jacobian[i, j])};" for i in range(6) for j in range(n)),
            "}",
            "",
        ]
        return "\n".join(lines)
    raise InputError("format", "text, latex, json, python or c for kinematics", repr(format))
