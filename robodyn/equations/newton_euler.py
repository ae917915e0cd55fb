"""The recursive Newton–Euler algorithm, symbolically: one program for every user.

``tau = M(q) q̈ + C(q, q̇) q̇ + G(q)`` of a fixed-base tree in O(n): a forward pass of every
body's angular velocity, angular acceleration and origin acceleration (gravity enters as an
upward acceleration of the base), a backward pass of each subtree's force and moment, each
projected on its joint's axis. Written as a straight-line program
(:class:`robodyn.equations.program.Program`) in the conventions of the compact equations:

- every quantity lives in its own body's frame, so masses, centres of mass and inertias are
  constants (sparse for most URDFs) and only the parent-to-body rotations depend on ``q``;
  rotation and axis entries within ``snap`` of 0, ±1, ±½, ±√2/2, ±√3/2 are exact, so a
  joint about ±x, ±y, ±z costs only its ``cos`` and ``sin``;
- a variable is made only for a non-trivial expression (:class:`ProgramBuilder`);
- mimic joints: every body moves with ``theta = S q + offset`` (``thetȧ = S q̇``,
  ``thetä = S q̈``) and ``tau = Sᵀ tau_bodies``.

The pieces are public so that the users share them: :func:`symbolic_bodies` (the
``q``-dependent frames, built once), :func:`newton_euler` (one pass pair, with or without
speeds, accelerations and gravity: the compact equations run it for ``C q̇`` and for ``G``)
and :func:`derive_newton_euler` (the whole program of ``tau``: the compiled ``tau`` kernel).
The free base's tree and symbols are in :mod:`robodyn.equations.free_base` (re-exported here).

No Pinocchio here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn.equations.free_base import BaseSymbols
from robodyn.equations.free_base import floating_reference as floating_reference  # re-exported
from robodyn.equations.free_base import floating_tree as floating_tree  # re-exported
from robodyn.equations.program import Program, ProgramBuilder
from robodyn.exceptions import InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, axis_rotation, body_coordinates, exact_matrix, joint_symbols

#: Default tolerance for exact rotation and axis entries of the program: float rounding only
#: (cos(π/2) = 6e-17), so the program is the URDF's robot. The printed equations snap more
#: (:data:`robodyn.equations.compact.SNAP`): a URDF's 1.5707963 then prints as π/2.
SNAP = 1e-15

_ZERO = sp.zeros(3, 1)


@dataclass(frozen=True)
class SymbolicBody:
    """One body of the tree, in its own frame, with exact constants.

    Attributes:
        parent: Index of the parent body, -1 for the fixed root.
        revolute: Revolute (else prismatic) joint.
        axis: Joint axis in the body frame, 3×1.
        rotation: Parent frame <- body frame, 3×3, in the program's symbols.
        translation: Body origin in the parent frame, 3×1, in [m].
        massive: Whether it has mass or inertia (else it carries no force of its own).
        mass: In [kg]; com: centre of mass in the body frame, 3×1, in [m];
            inertia: about the centre of mass, body axes, 3×3, in [kg m²].
    """

    parent: int
    revolute: bool
    axis: sp.Matrix
    rotation: sp.Matrix
    translation: sp.Matrix
    massive: bool
    mass: sp.Expr
    com: sp.Matrix
    inertia: sp.Matrix


@dataclass(frozen=True)
class Motion:
    """What the forward pass gives, body by body, in each body's frame (3×1 each).

    Attributes:
        angular_velocity, angular_acceleration: Of the body.
        acceleration: Of the body's origin (with the base's upward ``-g`` where gravity is in).
    """

    angular_velocity: list[sp.Matrix]
    angular_acceleration: list[sp.Matrix]
    acceleration: list[sp.Matrix]


def check_fixed_base(robot: ReferenceRobot) -> None:
    """Refuse a floating base (its six virtual joints are not Pinocchio's coordinates).

    Args:
        robot: The reference robot.

    Raises:
        InputError: For a floating-base robot.
    """
    if robot.floating_base:
        raise InputError(
            "robot",
            "a fixed-base robot (floating_base=False): the Newton–Euler program models fixed bases",
            f"a floating {robot.name}",
        )


def symbolic_bodies(
    robot: ReferenceRobot,
    theta: Sequence[sp.Expr],
    builder: ProgramBuilder,
    params: Parameters,
    *,
    snap: float,
    progress: Callable[[str, int, int], None] | None = None,
) -> list[SymbolicBody]:
    """Every body's frame (``cos``/``sin`` of its angle, rotation, or offset along its axis)
    as assignments of ``builder``, and its inertial constants.

    Args:
        robot: A fixed-base reference robot (mimic joints as bodies of their own).
        theta: Each body's coordinate, an expression in the program's inputs.
        builder: Receives the assignments (names ``c<b>_``, ``s<b>_``, ``R<b>_``, ``t<b>_``).
        params: Exact numbers, or symbols for kept parameters.
        snap: Tolerance for exact rotation and axis entries.
        progress: Called as ``progress("kinematics", done, total)``.
    """
    bodies = robot.tree.bodies
    result = []
    for b, body in enumerate(bodies):
        if progress:
            progress("kinematics", b, len(bodies))
        axis = exact_matrix(body.axis[:, None], snap)
        rotation = exact_matrix(body.origin[:3, :3], snap)
        translation = params.vector(body.origin[:3, 3], "d", body.joint)
        if body.revolute:
            c = builder.let(sp.cos(theta[b]), f"c{b + 1}_")
            s = builder.let(sp.sin(theta[b]), f"s{b + 1}_")
            builder.pair(c, s)
            rotation = builder.matrix(rotation * axis_rotation(axis, c, s), f"R{b + 1}_")
        else:
            translation = builder.vector(translation + rotation * axis * theta[b], f"t{b + 1}_")
        massive = bool(body.mass != 0 or body.inertia.any())
        result.append(
            SymbolicBody(
                parent=body.parent,
                revolute=body.revolute,
                axis=axis,
                rotation=rotation,
                translation=translation,
                massive=massive,
                mass=params.symbol(body.mass, "m", body.link) if massive else sp.Integer(0),
                com=params.vector(body.com, "c", body.link) if massive else _ZERO,
                inertia=params.inertia(body.inertia, body.link) if massive else sp.zeros(3, 3),
            )
        )
    return result


def forward_pass(
    bodies: Sequence[SymbolicBody],
    builder: ProgramBuilder,
    *,
    speed: Sequence[sp.Expr] | None = None,
    acceleration: Sequence[sp.Expr] | None = None,
    base_acceleration: sp.Matrix | None = None,
    tag: str = "",
    base_velocity: sp.Matrix | None = None,
    base_angular_acceleration: sp.Matrix | None = None,
) -> Motion:
    """Angular velocities and accelerations and origin accelerations, parents first.

    Args:
        bodies: From :func:`symbolic_bodies`.
        builder: Receives the assignments (names ``<tag>wi<b>_``, ``<tag>w<b>_``, ...).
        speed, acceleration: Each body's ``thetȧ``, ``thetä`` (``None``: zero).
        base_acceleration: The fixed root's acceleration in its frame, ``-g`` for gravity
            (``None``: zero).
        tag: Put in front of the names, to tell passes apart.
        base_velocity, base_angular_acceleration: Of the frame body 0 hangs from, in its
            frame (a free base, :func:`floating_tree`; ``None``: zero); the other roots
            (armature rotors) hang from a frame that does not turn.
    """
    count = len(bodies)
    w, dw, acc = [_ZERO] * count, [_ZERO] * count, [_ZERO] * count  # each set (parents first) before it is read
    base_w = _ZERO if base_velocity is None else base_velocity
    base_dw = _ZERO if base_angular_acceleration is None else base_angular_acceleration
    for b, body in enumerate(bodies):
        root = body.parent < 0
        w_p, dw_p = ((base_w, base_dw) if b == 0 else (_ZERO, _ZERO)) if root else (w[body.parent], dw[body.parent])
        a_p = (_ZERO if base_acceleration is None else base_acceleration) if root else acc[body.parent]
        t, Rt = body.translation, body.rotation.T
        w_in = builder.vector(Rt * w_p, f"{tag}wi{b + 1}_")
        origin = Rt * (a_p + dw_p.cross(t) + w_p.cross(w_p.cross(t)))
        spin = _ZERO if speed is None else body.axis * speed[b]
        push = _ZERO if acceleration is None else body.axis * acceleration[b]
        if body.revolute:
            w[b] = builder.vector(w_in + spin, f"{tag}w{b + 1}_")
            dw[b] = builder.vector(Rt * dw_p + w_in.cross(spin) + push, f"{tag}dw{b + 1}_")
            acc[b] = builder.vector(origin, f"{tag}a{b + 1}_")
        else:
            w[b] = w_in
            dw[b] = builder.vector(Rt * dw_p, f"{tag}dw{b + 1}_")
            acc[b] = builder.vector(origin + 2 * w_in.cross(spin) + push, f"{tag}a{b + 1}_")
    return Motion(w, dw, acc)


def backward_pass(
    bodies: Sequence[SymbolicBody], builder: ProgramBuilder, motion: Motion, *, tag: str = ""
) -> tuple[list[sp.Matrix], list[sp.Matrix]]:
    """Each subtree's force and moment (about the body's origin) in the body's frame,
    children first: ``(forces, moments)``, 3×1 each.

    Args:
        bodies: The tree's bodies (:func:`symbolic_bodies`).
        builder: The program the variables are added to.
        motion: The forward pass's result (:func:`forward_pass`).
        tag: Appended to the variables' names (keeps two passes of one program apart).
    """
    count = len(bodies)
    force, moment = [_ZERO] * count, [_ZERO] * count
    for b in reversed(range(count)):
        body = bodies[b]
        if body.massive:
            w, dw, com, inertia = motion.angular_velocity[b], motion.angular_acceleration[b], body.com, body.inertia
            com_acc = motion.acceleration[b] + dw.cross(com) + w.cross(w.cross(com))
            f = builder.vector(body.mass * com_acc, f"{tag}f{b + 1}_")
            force[b] = force[b] + f
            moment[b] = moment[b] + inertia * dw + w.cross(inertia * w) + com.cross(f)
        force[b] = builder.vector(force[b], f"{tag}F{b + 1}_")
        moment[b] = builder.vector(moment[b], f"{tag}N{b + 1}_")
        if body.parent >= 0:
            pushed = body.rotation * force[b]
            force[body.parent] = force[body.parent] + pushed
            moment[body.parent] = moment[body.parent] + body.rotation * moment[b] + body.translation.cross(pushed)
    return force, moment


def project(body: SymbolicBody, moment: sp.Matrix, force: sp.Matrix) -> sp.Expr:
    """The joint's share of a moment and force in the body's frame: the moment about a
    revolute axis, the force along a prismatic one.

    Args:
        body: The body its joint moves.
        moment: About the body's origin, body frame, 3×1.
        force: Body frame, 3×1.
    """
    return (body.axis.T * (moment if body.revolute else force))[0]


def newton_euler(
    bodies: Sequence[SymbolicBody],
    builder: ProgramBuilder,
    *,
    speed: Sequence[sp.Expr] | None = None,
    acceleration: Sequence[sp.Expr] | None = None,
    base_acceleration: sp.Matrix | None = None,
    tag: str = "",
) -> list[sp.Expr]:
    """One body's joint force a body: :func:`forward_pass`, :func:`backward_pass`, :func:`project`.

    With all three of ``speed``, ``acceleration``, ``base_acceleration = -g`` this is
    ``tau``; with the speed alone ``C q̇``; with gravity alone ``G``; with the acceleration
    alone ``M q̈`` (of the bodies' coordinates).
    """
    motion = forward_pass(bodies, builder, speed=speed, acceleration=acceleration, base_acceleration=base_acceleration, tag=tag)
    force, moment = backward_pass(bodies, builder, motion, tag=tag)
    return [project(body, moment[b], force[b]) for b, body in enumerate(bodies)]


def free_base_newton_euler(
    bodies: Sequence[SymbolicBody],
    builder: ProgramBuilder,
    *,
    speed: Sequence[sp.Expr] | None = None,
    acceleration: Sequence[sp.Expr] | None = None,
    base_velocity: Sequence[sp.Expr] | None = None,
    base_acceleration: Sequence[sp.Expr] | None = None,
    gravity: sp.Matrix | None = None,
    tag: str = "",
) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """:func:`newton_euler` with body 0 a free base (:func:`floating_tree`).

    Args:
        bodies, builder, speed, acceleration, tag: As :func:`newton_euler`.
        base_velocity: The base's linear then angular velocity in its frame (6; ``None``: 0).
        base_acceleration: Pinocchio's base ``v̇`` (6; ``None``: 0).
        gravity: Gravity in the base frame, 3×1 (``None``: none).

    Returns:
        ``(base, joints)``: the force then moment the tree needs at the base origin, in the
        base frame (Pinocchio's base rows of ``tau``), and each body's joint force.
    """
    linear, angular, spin = sp.zeros(3, 1), None, None
    if base_velocity is not None:
        angular = sp.Matrix(base_velocity[3:])
        linear += angular.cross(sp.Matrix(base_velocity[:3]))
    if base_acceleration is not None:
        linear += sp.Matrix(base_acceleration[:3])
        spin = sp.Matrix(base_acceleration[3:])
    if gravity is not None:
        linear -= gravity
    origin = builder.vector(linear, f"{tag}ab_")
    motion = forward_pass(
        bodies,
        builder,
        speed=speed,
        acceleration=acceleration,
        base_acceleration=origin,
        tag=tag,
        base_velocity=angular,
        base_angular_acceleration=spin,
    )
    force, moment = backward_pass(bodies, builder, motion, tag=tag)
    return [*force[0], *moment[0]], [project(body, moment[b], force[b]) for b, body in enumerate(bodies)]


def derive_newton_euler(
    robot: ReferenceRobot,
    *,
    snap: float = SNAP,
    keep_params: bool = False,
    symbols: tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]] | None = None,
    free_base: BaseSymbols | None = None,
) -> Program:
    """``tau(q, q̇, q̈)`` of a fixed-base reference robot as a straight-line program.

    Args:
        robot: From :func:`robodyn.reference.load` (mimic joints included).
        snap: Tolerance for exact rotation and axis entries.
        keep_params: Keep masses, centres of mass, inertias, joint offsets and gravity as
            symbols (:class:`robodyn.reference.symbolic.Parameters`; in the program's
            ``parameters``).
        symbols: ``(q, qd, qdd)`` to use instead of the reference's joint symbols.
        free_base: Body 0 is a free base (``robot`` from :func:`floating_reference`) with
            these inputs: the program has inputs ``base_q``, ``base_v``, ``base_a`` too and
            an output ``base`` (its force then moment, Pinocchio's base rows of ``tau``).

    Returns:
        Inputs ``q``, ``qd``, ``qdd`` (order of ``robot.joint_names``), output ``tau``
        (same order), in [N m] / [N].

    Raises:
        InputError: For a floating base.
    """
    check_fixed_base(robot)
    q, qd, qdd = symbols or joint_symbols(robot.joint_names)
    theta, theta_dot = body_coordinates(robot, q, qd)
    theta_ddot = exact_matrix(robot.tree.selection, 0.0) * sp.Matrix(qdd)
    params = Parameters(keep_params)
    builder = ProgramBuilder()
    bodies = symbolic_bodies(robot, list(theta), builder, params, snap=snap)
    inputs = {"q": tuple(q), "qd": tuple(qd), "qdd": tuple(qdd)}
    outputs: dict[str, list[sp.Expr]] = {}
    if free_base is None:
        gravity = -params.gravity(robot.gravity_vector)  # the base "accelerates upwards"
        tau_bodies = newton_euler(
            bodies, builder, speed=list(theta_dot), acceleration=list(theta_ddot), base_acceleration=gravity
        )
    else:
        outputs["base"], tau_bodies = free_base_newton_euler(
            bodies,
            builder,
            speed=list(theta_dot),
            acceleration=list(theta_ddot),
            base_velocity=free_base.velocity,
            base_acceleration=free_base.acceleration,
            gravity=builder.vector(free_base.gravity(params.gravity(robot.gravity_vector)), "gb_"),
        )
        inputs.update(base_q=free_base.quaternion, base_v=free_base.velocity, base_a=free_base.acceleration)
    tau = exact_matrix(robot.tree.selection, 0.0).T * sp.Matrix(tau_bodies)  # tau = Sᵀ tau_bodies
    program = builder.program(inputs, {"tau": list(tau), **outputs})
    return Program(program.inputs, program.assignments, program.outputs, params.values, params.labels)
