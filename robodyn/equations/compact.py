"""Compact closed-form dynamics for real arms: the Lagrangian in intermediate variables.

Fully expanded closed forms explode beyond three or four joints (ur5's ``M(q)`` alone
grows past a million operations). This module derives the same equations as a short
program of named assignments, the way SYMORO prints customised models:

- every quantity lives in its own body's frame (:func:`robodyn.equations.newton_euler.symbolic_bodies`):
  link masses, centres of mass and inertias are constants and only the parent-to-body
  rotations depend on ``q``; rotation and axis entries within ``snap`` of 0, ±1, ±½,
  ±√2/2, ±√3/2 are exact, so a joint about ±x, ±y, ±z costs only its ``cos`` and ``sin``;
- ``C q̇ + G``: the Lagrangian ``d/dt ∂T/∂q̇ − ∂T/∂q + ∂U/∂q`` summed body by body is the
  rate of change of each subtree's momentum projected on the joint axis: the Newton–Euler
  program (:func:`robodyn.equations.newton_euler.newton_euler`), once with the speeds for
  ``C q̇`` and once with gravity alone for ``G``;
- ``M``: column ``i`` is the composite body beyond joint ``i`` moving along its axis,
  carried up to each ancestor ``j`` and projected on joint ``j``'s axis;
- a variable is made only for a non-trivial expression, ``cos²`` or ``sin²`` of a joint
  is replaced by ``1 − sin²`` / ``1 − cos²`` where that shortens it, ``sympy.cse`` then
  shares what is still repeated, and copies (``a = b``) are substituted away
  (:mod:`robodyn.equations.sharing`);
- mimic joints: every body moves with ``theta = S q + offset``; the equations of the bodies
  are mapped with ``M = Sᵀ M_full S``, ``C q̇ = Sᵀ (C q̇)_full``, ``G = Sᵀ G_full``;
- with ``keep_params`` masses, centres of mass, inertias, joint offsets and gravity are
  symbols (:class:`robodyn.reference.symbolic.Parameters`).

No Pinocchio here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import sympy as sp

from robodyn.equations.newton_euler import (
    BaseSymbols,
    SymbolicBody,
    check_fixed_base,
    free_base_newton_euler,
    newton_euler,
    project,
    symbolic_bodies,
)
from robodyn.equations.program import Program, ProgramBuilder
from robodyn.equations.sharing import shortened, without_copies
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, body_coordinates, exact_matrix, joint_symbols

#: Default tolerance for exact rotation and axis entries: loose enough that a URDF's
#: 1.5707963 prints as π/2 (the equations are for reading; the compiled engine passes 1e-15).
SNAP = 1e-8


@dataclass
class CompactDynamics:
    """``tau = M q̈ + C q̇ + G`` as assignments followed by output expressions.

    Attributes:
        q, qd, qdd: Joint symbols (order of the reference's ``joint_names``).
        assignments: ``(symbol, expression)`` pairs, in evaluation order.
        M: Mass matrix entries in terms of the assigned symbols.
        Cv: ``C(q, q̇) q̇`` entries.
        G: Gravity entries.
        parameters: Kept parameters and their values (``keep_params``).
        labels: ``(kind, owner, component)`` of every kept parameter.
        base: With a free base (``free_base``): its inputs, and its rows ``M`` (6 × (6 +
            bodies): the base block, then the bodies' columns), ``Cv`` and ``G`` (6 each),
            Pinocchio's order (force then moment).
    """

    q: list[sp.Symbol]
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    assignments: list[tuple[sp.Symbol, sp.Expr]] = field(default_factory=list)
    M: sp.Matrix = field(default_factory=sp.Matrix)
    Cv: sp.Matrix = field(default_factory=sp.Matrix)
    G: sp.Matrix = field(default_factory=sp.Matrix)
    parameters: dict = field(default_factory=dict)
    labels: dict = field(default_factory=dict)
    base: BaseSymbols | None = None
    base_rows: dict[str, sp.Matrix] = field(default_factory=dict)

    def program(self) -> Program:
        """The same as a :class:`~robodyn.equations.program.Program` (inputs ``q``, ``qd``;
        outputs ``M`` row-major, ``Cv``, ``G``)."""
        inputs = {"q": tuple(self.q), "qd": tuple(self.qd)}
        outputs = {"M": tuple(self.M), "Cv": tuple(self.Cv), "G": tuple(self.G)}
        if self.base is not None:
            inputs.update(base_q=self.base.quaternion, base_v=self.base.velocity)
            outputs.update({f"base_{name}": tuple(rows) for name, rows in self.base_rows.items()})
        return Program(inputs, tuple(self.assignments), outputs, self.parameters, self.labels)


def _composites(
    bodies: Sequence[SymbolicBody], builder: ProgramBuilder
) -> tuple[list[sp.Expr], list[sp.Matrix], list[sp.Matrix]]:
    """Every subtree's mass, first moment ``m c`` (3×1) and inertia about the body's origin
    (3×3), in the body's frame, children first."""
    count = len(bodies)
    mass: list[sp.Expr] = [sp.Integer(0)] * count
    first: list[sp.Matrix] = [sp.zeros(3, 1)] * count
    inertia: list[sp.Matrix] = [sp.zeros(3, 3)] * count
    for b in reversed(range(count)):
        body = bodies[b]
        if body.massive:
            com = body.com
            mass[b] = mass[b] + body.mass
            first[b] = first[b] + body.mass * com
            inertia[b] = inertia[b] + body.inertia + body.mass * ((com.T * com)[0] * sp.eye(3) - com * com.T)
        first[b] = builder.vector(first[b], f"h{b + 1}_")
        inertia[b] = builder.matrix(inertia[b], f"I{b + 1}_")
        parent, R, t = body.parent, body.rotation, body.translation
        if parent >= 0:  # the child's composite, moved to the parent's origin
            h = R * first[b]
            shift = mass[b] * ((t.T * t)[0] * sp.eye(3) - t * t.T)
            cross = 2 * (t.T * h)[0] * sp.eye(3) - t * h.T - h * t.T
            mass[parent] = mass[parent] + mass[b]
            first[parent] = first[parent] + h + mass[b] * t
            inertia[parent] = inertia[parent] + R * inertia[b] * R.T + shift + cross
    return mass, first, inertia


def _mass_matrix(bodies: Sequence[SymbolicBody], builder: ProgramBuilder, base: sp.Matrix | None = None) -> sp.Matrix:
    """``M`` of the bodies' coordinates: column ``i`` is the composite body beyond joint ``i``
    moving along its axis, carried up to each ancestor and projected on its axis.

    With ``base`` (6 × bodies, zeros; body 0 a free base) its columns are filled with the
    force then moment that reach body 0, unprojected."""
    mass, first, inertia = _composites(bodies, builder)
    if base is not None:
        _base_block(base, mass[0], first[0], inertia[0])
    count = len(bodies)
    M = sp.zeros(count, count)
    for i, body in enumerate(bodies):
        if body.revolute:
            n, f = inertia[i] * body.axis, body.axis.cross(first[i])
        else:
            n, f = first[i].cross(body.axis), mass[i] * body.axis
        n, f = builder.vector(n, f"Mn{i + 1}_"), builder.vector(f, f"Mf{i + 1}_")
        j = i
        while j >= 0:
            M[i, j] = M[j, i] = project(bodies[j], n, f)
            if base is not None and j == 0 and i > 0:
                base[:, 6 + i] = sp.Matrix([*f, *n])
            parent = bodies[j].parent
            if parent < 0:
                break
            f_up = bodies[j].rotation * f
            n, f = (
                builder.vector(bodies[j].rotation * n + bodies[j].translation.cross(f_up), f"Mn{i + 1}_{parent + 1}_"),
                builder.vector(f_up, f"Mf{i + 1}_{parent + 1}_"),
            )
            j = parent
    return M


def _base_block(base: sp.Matrix, mass: sp.Expr, first: sp.Matrix, inertia: sp.Matrix) -> None:
    """The base-base block of a free base: the whole tree's spatial inertia at the base origin,
    ``[[m 1, −[h]×], [[h]×, I_o]]`` (``h = m c``), into ``base[:, :6]``."""
    x, y, z = first
    hx = sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    base[:3, :3] = mass * sp.eye(3)
    base[:3, 3:6] = -hx
    base[3:6, :3] = hx
    base[3:6, 3:6] = inertia


def _free_base_equations(
    bodies: Sequence[SymbolicBody], builder: ProgramBuilder, params: Parameters, robot: ReferenceRobot, theta_dot, free_base
) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix, dict[str, sp.Matrix]]:
    """``M``, ``C v``, ``G`` of the bodies and the base's rows, body 0 a free base."""
    gravity = builder.vector(free_base.gravity(params.gravity(robot.gravity_vector)), "gb_")
    velocity = free_base.velocity
    base_cv, Cv = free_base_newton_euler(bodies, builder, speed=list(theta_dot), base_velocity=velocity)
    base_g, G = free_base_newton_euler(bodies, builder, gravity=gravity, tag="g")
    base_m = sp.zeros(6, 6 + len(bodies))
    M = _mass_matrix(bodies, builder, base_m)
    return M, sp.Matrix(Cv), sp.Matrix(G), {"M": base_m, "Cv": sp.Matrix(base_cv), "G": sp.Matrix(base_g)}


def derive_compact(
    robot: ReferenceRobot,
    *,
    snap: float = SNAP,
    cse: bool = True,
    keep_params: bool = False,
    symbols: tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]] | None = None,
    progress: Callable[[str, int, int], None] | None = None,
    free_base: BaseSymbols | None = None,
) -> CompactDynamics:
    """Derive the compact (intermediate-variable) equations of a reference robot.

    Args:
        robot: From :func:`robodyn.reference.load` (mimic joints included; fixed base).
        snap: Tolerance for exact rotation and axis entries.
        cse: Share repeated subexpressions with ``sympy.cse`` at the end.
        keep_params: Keep masses, centres of mass, inertias, joint offsets and gravity as
            symbols (see :class:`robodyn.reference.symbolic.Parameters`).
        symbols: ``(q, qd, qdd)`` to use instead of the reference's joint symbols.
        progress: Called as ``progress(stage, done, total)``.
        free_base: Body 0 is a free base (``robot`` from
            :func:`robodyn.equations.newton_euler.floating_reference`) with these inputs:
            the result's ``base_rows`` are its rows of ``M``, ``C v`` and ``G``.

    Raises:
        InputError: For a floating base.
    """
    check_fixed_base(robot)
    q, qd, qdd = symbols or joint_symbols(robot.joint_names)
    theta, theta_dot = body_coordinates(robot, q, qd)
    params = Parameters(keep_params)
    builder = ProgramBuilder(pythagoras=True)
    bodies = symbolic_bodies(robot, list(theta), builder, params, snap=snap, progress=progress)
    if progress:
        progress("Newton-Euler", 0, 3)
    base_rows: dict[str, sp.Matrix] = {}
    if free_base is not None:
        M, Cv, G, base_rows = _free_base_equations(bodies, builder, params, robot, theta_dot, free_base)
    else:
        Cv = sp.Matrix(newton_euler(bodies, builder, speed=list(theta_dot)))
        if progress:
            progress("Newton-Euler", 1, 3)
        G = sp.Matrix(newton_euler(bodies, builder, base_acceleration=-params.gravity(robot.gravity_vector), tag="g"))
        if progress:
            progress("composite bodies", 2, 3)
        M = _mass_matrix(bodies, builder)
    selection = exact_matrix(robot.tree.selection, 0.0)
    if selection != sp.eye(len(bodies)):  # mimic joints: tau = Sᵀ tau_full, theta'' = S q''
        M, Cv, G = selection.T * M * selection, selection.T * Cv, selection.T * G
        if base_rows:
            base_rows["M"] = base_rows["M"][:, :6].row_join(base_rows["M"][:, 6:] * selection)
    inputs = {"q": tuple(q), "qd": tuple(qd)}
    outputs: dict[str, Sequence[sp.Expr]] = {"M": list(M), "Cv": list(Cv), "G": list(G)}
    if free_base is not None:
        inputs.update(base_q=free_base.quaternion, base_v=free_base.velocity)
        outputs.update({f"base_{name}": list(rows) for name, rows in base_rows.items()})
    program = builder.program(inputs, outputs)
    if cse:
        if progress:
            progress("common subexpressions", 0, 1)
        program = shortened(program)
    program = without_copies(program)
    n = len(q)
    base_rows = {
        name: sp.Matrix(base_rows[name].rows, base_rows[name].cols, list(program.outputs[f"base_{name}"])) for name in base_rows
    }
    return CompactDynamics(
        q,
        qd,
        qdd,
        list(program.assignments),
        sp.Matrix(n, n, list(program.outputs["M"])),
        sp.Matrix(program.outputs["Cv"]),
        sp.Matrix(program.outputs["G"]),
        params.values,
        params.labels,
        free_base,
        base_rows,
    )
