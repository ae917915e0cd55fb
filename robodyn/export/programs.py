"""The straight-line programs a robot's exported functions are printed from.

The equations layer derives them, once per robot for the compiled engine and the export
alike (:mod:`robodyn.compiled.programs`: kept in memory and pickled in the compiled cache,
under the robot's key; kept parameters are derived at each call):
the compact program (:func:`robodyn.equations.compact.derive_compact`: ``M``, ``C v``, ``G``)
and the Newton–Euler program (:func:`robodyn.equations.newton_euler.derive_newton_euler`:
``tau`` in O(n); at zero acceleration and shortened, ``C v + G`` in one pass: smaller than
the compact program's two passes), both over the bodies' coordinates (mimic joints as bodies of their own),
plus one program of every body's world pose (:func:`frame_program`) from which each frame's
position and Jacobian are read. The robot's coordinates map onto the bodies' by its linear
map ``theta = S q + offset``; the printer (:mod:`robodyn.export.source`) projects back
(``tau = Sᵀ tau_bodies``, ``M = Sᵀ M_bodies S``, ``J = J_bodies S``). The dynamics'
programs are printed with their sums' common factors taken out
(:func:`robodyn.export.factoring.factored`: ur5's M + C v + G 963 -> 893 CasADi instructions).

Frames are Pinocchio's (:attr:`robodyn.Robot.frame_names`: links, joints, fixed frames):
a frame is its parent joint's body and a constant placement, so the exported positions and
Jacobians are the ones :meth:`robodyn.Robot.frame_position` and
:meth:`robodyn.Robot.frame_jacobian` give (world-aligned, linear rows first).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn.compiled.cache import SNAP
from robodyn.compiled.programs import Bodies, derived, dynamics_programs, robot_bodies
from robodyn.compiled.robot import coordinate_parents
from robodyn.dynamics.robot import Robot
from robodyn.equations.compact import derive_compact
from robodyn.equations.newton_euler import derive_newton_euler, symbolic_bodies
from robodyn.equations.program import Program, ProgramBuilder
from robodyn.equations.sharing import shortened
from robodyn.exceptions import InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, exact_matrix, joint_symbols


@dataclass(frozen=True)
class ExportPrograms:
    """Everything the exported module is printed from.

    Attributes:
        robot: Robot name (raw; the printer escapes it).
        joint_names: The order of ``q``, ``v``, ``a``, ``tau`` (raw).
        selection: ``S``, shape (n_bodies, nv): ``theta = S q + offset``.
        offset: Shape (n_bodies,), in [rad] / [m].
        parents: Parent coordinate of each coordinate (-1 at a root), for the tree LDLᵀ.
        symbols: The bodies' ``(theta, thetȧ, thetä)`` symbols the programs use.
        dynamics: Compact program over the bodies: outputs ``M`` (row-major), ``Cv``, ``G``.
        tau: Newton–Euler program over the bodies: output ``tau``.
        nle: The same at zero acceleration (``C v + G`` in one pass), shortened
            (:func:`robodyn.equations.sharing.shortened`): output ``tau``.
        frames: Outputs ``p<k>`` (3, world position) and ``J<k>`` (6 × n_bodies, row-major)
            of each frame ``frame_names[k]``, in the bodies' coordinates.
        frame_names: The exported frames (raw names).
        parameters: Kept parameters (``keep_params``) in the order of the extra input, with
            their values.
    """

    robot: str
    joint_names: list[str]
    selection: np.ndarray
    offset: np.ndarray
    parents: list[int]
    symbols: tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]]
    dynamics: Program
    tau: Program
    nle: Program
    frames: Program
    frame_names: list[str]
    parameters: dict[sp.Symbol, float]


def check_exportable(robot: Robot) -> None:
    """Refuse a floating base or a robot without moving joints, in one sentence.

    Args:
        robot: The loaded robot.

    Raises:
        InputError: A floating base, or no moving joint.
    """
    if robot.floating_base:
        raise InputError(
            "robot", "a fixed-base robot (floating_base=False): exported functions model fixed bases", f"a floating {robot.name}"
        )
    if robot.nv == 0:
        raise InputError("robot", "a robot with moving joints", f"{robot.name} with none")


def export_programs(
    robot: Robot,
    *,
    frames: Sequence[str] | None = None,
    keep_params: bool = False,
    progress: Callable[[str, int, int], None] | None = None,
) -> ExportPrograms:
    """The programs of a fixed-base robot's exported functions: derived once per robot (a sympy
    derivation: seconds for a 7-joint arm), shared with :func:`robodyn.compiled.compile` and
    kept in the compiled cache (:mod:`robodyn.compiled.programs`), so a second call or one
    after ``compile`` reads them; kept parameters (``keep_params``) are derived each call.

    Args:
        robot: From :func:`robodyn.load` (fixed base; mimic and locked joints as loaded).
        frames: Frames to export (names of :attr:`robodyn.Robot.frame_names`); ``None``: all.
        keep_params: Masses, centres of mass, inertias, joint offsets and gravity as an
            extra input (see :class:`robodyn.reference.symbolic.Parameters`).
        progress: Called as ``progress(stage, done, total)`` during the derivation.

    Raises:
        InputError: For a floating base or a robot without moving joints.
        FrameError: For a frame the robot does not have.
    """
    check_exportable(robot)
    names = list(robot.frame_names) if frames is None else [str(frame) for frame in frames]
    for frame in names:
        robot.frame_id(frame)  # FrameError with the closest names
    bodies = robot_bodies(robot)
    dynamics, tau, symbols = _dynamics(robot, bodies, keep_params, progress)
    if progress:
        progress("Newton-Euler", 0, 1)
    placements = [_placement(robot, frame, bodies.tree) for frame in names]

    def kinematics_program() -> Program:
        return frame_program(bodies.reference, symbols[0], placements, keep_params=keep_params)

    if keep_params:
        nle, kinematics = _at_rest(tau, symbols[2]), kinematics_program()
    else:  # derived once per robot, as its dynamics
        nle = derived(robot, "export nle", lambda: _at_rest(tau, symbols[2]))
        kinematics = derived(robot, "export frames\0" + "\0".join(names), kinematics_program)
    parameters = {**dynamics.parameters, **tau.parameters, **kinematics.parameters}
    return ExportPrograms(
        robot=robot.name,
        joint_names=list(robot.joint_names),
        selection=bodies.selection,
        offset=bodies.offset,
        parents=coordinate_parents(robot),
        symbols=symbols,
        dynamics=dynamics,
        tau=tau,
        nle=nle,
        frames=kinematics,
        frame_names=names,
        parameters=dict(sorted(parameters.items(), key=lambda item: str(item[0]))),
    )


def _dynamics(
    robot: Robot, bodies: Bodies, keep_params: bool, progress: Callable[[str, int, int], None] | None
) -> tuple[Program, Program, tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]]]:
    """The compact program, the Newton–Euler program and their ``(q, q̇, q̈)`` symbols: the
    compiled engine's, derived once per robot (:func:`robodyn.compiled.programs.dynamics_programs`),
    or, with kept parameters, derived here."""
    if not keep_params:
        shared = dynamics_programs(robot)
        return shared.compact.program(), shared.tau, (shared.compact.q, shared.compact.qd, shared.compact.qdd)
    symbols = joint_symbols(bodies.reference.joint_names)
    dynamics = derive_compact(bodies.reference, snap=SNAP, keep_params=True, symbols=symbols, progress=progress)
    return dynamics.program(), derive_newton_euler(bodies.reference, snap=SNAP, keep_params=True, symbols=symbols), symbols


def _at_rest(tau: Program, accelerations: Sequence[sp.Symbol]) -> Program:
    """``tau`` at zero acceleration (``C v + G`` in one pass), shortened."""
    still = {symbol: sp.Integer(0) for symbol in accelerations}
    return shortened(
        Program(
            tau.inputs,
            tuple((symbol, expr.xreplace(still)) for symbol, expr in tau.assignments),
            {"tau": tuple(expr.xreplace(still) for expr in tau.outputs["tau"])},
        )
    )


def _placement(robot: Robot, frame: str, tree) -> tuple[int, np.ndarray]:
    """A frame as ``(body, translation)``: the body of its parent joint (-1 for the fixed
    base) and the frame's constant origin in that body's frame, in [m]."""
    model = robot.model
    placed = model.frames[robot.frame_id(frame)]
    joint = int(placed.parentJoint)
    bodies = {body.joint: index for index, body in enumerate(tree.bodies)}
    body = -1 if joint == 0 else bodies[model.names[joint]]
    return body, np.array(placed.placement.translation)


def frame_program(
    reference: ReferenceRobot,
    theta: Sequence[sp.Symbol],
    placements: Sequence[tuple[int, np.ndarray]],
    *,
    keep_params: bool = False,
) -> Program:
    """World position and Jacobian of frames carried by the bodies.

    Every body's world rotation and origin are assignments (parents first); a frame on body
    ``b`` at ``(R_f, p_f)`` is at ``p = p_b + R_b p_f``, and the column of each body ``i``
    carrying it is ``(z_i × (p − o_i), z_i)`` for a revolute joint, ``(z_i, 0)`` for a
    prismatic one (``z_i`` its world axis, ``o_i`` its world origin): Pinocchio's
    ``LOCAL_WORLD_ALIGNED`` Jacobian in the bodies' coordinates.

    Args:
        reference: The bodies (fixed base; one coordinate a body).
        theta: The bodies' coordinates.
        placements: Per frame ``(body, translation)`` (body -1: the fixed base).
        keep_params: Joint offsets as the kept parameters ``d_<joint>_x``...

    Returns:
        Inputs ``q`` (``theta``); outputs ``p<k>`` and ``J<k>`` per frame.
    """
    builder = ProgramBuilder()
    params = Parameters(keep_params)
    bodies = symbolic_bodies(reference, list(theta), builder, params, snap=SNAP)
    rotations: list[sp.Matrix] = []
    origins: list[sp.Matrix] = []
    for b, body in enumerate(bodies):
        parent_rotation = sp.eye(3) if body.parent < 0 else rotations[body.parent]
        parent_origin = sp.zeros(3, 1) if body.parent < 0 else origins[body.parent]
        rotations.append(builder.matrix(parent_rotation * body.rotation, f"W{b + 1}_"))
        origins.append(builder.vector(parent_origin + parent_rotation * body.translation, f"o{b + 1}_"))
    axes = [builder.vector(rotations[b] * body.axis, f"z{b + 1}_") for b, body in enumerate(bodies)]
    outputs: dict[str, Sequence[sp.Expr]] = {}
    count = len(bodies)
    for k, (b, translation) in enumerate(placements):
        offset = exact_matrix(np.asarray(translation)[:, None], 0.0)
        position = offset if b < 0 else builder.vector(origins[b] + rotations[b] * offset, f"p{k}_")
        jacobian = sp.zeros(6, count)
        for i in range(count):
            if b < 0 or not reference.tree.ancestors[b, i]:
                continue
            if bodies[i].revolute:
                jacobian[:3, i] = axes[i].cross(position - origins[i])
                jacobian[3:, i] = axes[i]
            else:
                jacobian[:3, i] = axes[i]
        outputs[f"p{k}"] = list(position)
        outputs[f"J{k}"] = list(jacobian)
    program = builder.program({"q": tuple(theta)}, outputs)
    return Program(program.inputs, program.assignments, program.outputs, params.values, params.labels)
