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
from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np
import sympy as sp

from robodyn import reference
from robodyn.common.rotations import rpy_matrix
from robodyn.common.text import identifier
from robodyn.equations import render_c, render_json, render_latex, render_python, render_text, simplify
from robodyn.equations.model import Kinematics
from robodyn.equations.newton_euler import check_fixed_base, forward_pass, symbolic_bodies
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision
from robodyn.equations.program import Program, ProgramBuilder
from robodyn.exceptions import FrameError, InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, body_coordinates, body_poses, exact_matrix, joint_symbols

KinematicsFormat = Literal["text", "latex", "json", "python", "c"]


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


def render_kinematics(kinematics: Kinematics, format: KinematicsFormat = "text", *, precision: int = DEFAULT_PRECISION) -> str:
    """The frame's position and Jacobian as ``text``, ``latex`` (a fragment), ``json``,
    ``python`` (a module with ``frame_position(q)`` and ``frame_jacobian(q)``) or ``c``
    (the same two functions, one state, arrays of doubles): one renderer a format, as for
    the equations (:func:`robodyn.equations.output.render`).

    Args:
        kinematics: The derived frame kinematics (:func:`robodyn.equations.kinematics.derive_kinematics`).
        format: ``"text"``, ``"latex"``, ``"json"``, ``"python"`` or ``"c"``.
        precision: Significant digits of the numbers printed, 1 to 17.

    Raises:
        InputError: For an unknown format or precision.
    """
    check_precision(precision)
    renderers: dict[str, Callable[[Kinematics], str]] = {
        "text": lambda k: render_text.kinematics_text(k, precision=precision),
        "latex": lambda k: render_latex.kinematics_latex(k, precision=precision),
        "json": render_json.kinematics_json,
        "python": render_python.kinematics_python,
        "c": render_c.kinematics_c,
    }
    if format not in renderers:
        raise InputError("format", "text, latex, json, python or c for kinematics", repr(format))
    return renderers[format](kinematics)


def frame_program(
    robot: ReferenceRobot,
    body: int,
    rotation: np.ndarray,
    translation: np.ndarray,
    *,
    snap: float = 1e-15,
    symbols: tuple[list[sp.Symbol], list[sp.Symbol]] | None = None,
) -> Program:
    """A frame's pose, Jacobian and bias acceleration as a straight-line program.

    The frame is fixed to a body of the reference tree (``body``, -1 for the fixed root) at
    ``rotation``/``translation`` in that body's frame. The program (built from the same
    body frames and forward pass as the Newton–Euler program,
    :func:`robodyn.equations.newton_euler.symbolic_bodies` and ``forward_pass``) has inputs
    ``q`` and ``qd`` (order of ``robot.joint_names``) and outputs, world axes:

    - ``position``: the frame's origin, 3, in [m]; ``rotation``: world <- frame, 9 (row-major);
    - ``jacobian``: 6 × nv row-major, rows 0-2 the origin's velocity, rows 3-5 the angular
      velocity (Pinocchio's ``LOCAL_WORLD_ALIGNED``);
    - ``bias``: ``J̇ q̇``, 6: the origin's classical acceleration in [m/s²] and the angular
      acceleration in [rad/s²] at zero joint acceleration.

    Args:
        robot: A fixed-base reference robot (mimic joints as bodies of their own).
        body: Index of the carrying body in ``robot.tree.bodies``, or -1.
        rotation: Body frame <- frame, shape (3, 3).
        translation: The frame's origin in the body frame, shape (3,), in [m].
        snap: Tolerance for exact rotation and axis entries.
        symbols: ``(q, qd)`` to use instead of the reference's joint symbols.
    """
    check_fixed_base(robot)
    q, qd = symbols or joint_symbols(robot.joint_names)[:2]
    theta, theta_dot = body_coordinates(robot, q, qd)
    selection = exact_matrix(robot.tree.selection, 0.0)
    builder = ProgramBuilder()
    bodies = symbolic_bodies(robot, list(theta), builder, Parameters(False), snap=snap)
    offset_rotation, offset = exact_matrix(np.asarray(rotation), snap), exact_matrix(np.asarray(translation)[:, None], snap)
    chain = [] if body < 0 else [i for i in range(body + 1) if robot.tree.ancestors[body, i]]
    world_rotation: dict[int, sp.Matrix] = {}
    world_position: dict[int, sp.Matrix] = {}
    for b in chain:  # parents first: tree order
        parent = bodies[b].parent
        parent_rotation = sp.eye(3) if parent < 0 else world_rotation[parent]
        parent_position = sp.zeros(3, 1) if parent < 0 else world_position[parent]
        world_position[b] = builder.vector(parent_position + parent_rotation * bodies[b].translation, f"p{b + 1}_")
        world_rotation[b] = builder.matrix(parent_rotation * bodies[b].rotation, f"R{b + 1}_")
    frame_rotation = offset_rotation if body < 0 else world_rotation[body] * offset_rotation
    lever = offset if body < 0 else world_rotation[body] * offset
    position = lever if body < 0 else builder.vector(world_position[body] + lever, "pf_")
    columns = sp.zeros(6, len(bodies))
    for b in chain:
        axis = builder.vector(world_rotation[b] * bodies[b].axis, f"z{b + 1}_")
        if bodies[b].revolute:
            columns[:3, b], columns[3:, b] = axis.cross(position - world_position[b]), axis
        else:
            columns[:3, b] = axis
    jacobian = columns * selection
    bias = sp.zeros(6, 1)
    if body >= 0:
        motion = forward_pass(bodies, builder, speed=list(theta_dot), tag="k")
        w, dw = motion.angular_velocity[body], motion.angular_acceleration[body]
        local = motion.acceleration[body] + dw.cross(offset) + w.cross(w.cross(offset))
        bias = (world_rotation[body] * local).col_join(world_rotation[body] * dw)
    outputs: dict[str, Sequence[sp.Expr]] = {
        "position": list(position),
        "rotation": list(frame_rotation),
        "jacobian": list(jacobian),
        "bias": list(bias),
    }
    return builder.program({"q": tuple(q), "qd": tuple(qd)}, outputs)
