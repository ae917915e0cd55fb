"""Compact closed-form dynamics for real arms: the Lagrangian in intermediate variables.

Fully expanded closed forms explode beyond three or four joints (ur5's ``M(q)`` alone
grows past a million operations). This module derives the same equations as a short
program of named assignments, the way SYMORO prints customised models:

- every quantity lives in its own body's frame, so link masses, centres of mass and
  inertias are constants (sparse for most URDFs) and only the parent-to-body rotations
  depend on ``q``; rotation and axis entries within ``snap`` of 0, ±1, ±½, ±√2/2, ±√3/2
  are exact, so a joint about ±x, ±y, ±z costs only its ``cos`` and ``sin``;
- ``C q̇ + G``: the Lagrangian ``d/dt ∂T/∂q̇ − ∂T/∂q + ∂U/∂q`` summed body by body is the
  rate of change of each subtree's momentum projected on the joint axis: a forward pass
  of angular velocities and velocity-product accelerations, a backward pass of forces and
  moments (the Newton–Euler form of the same equations), once with the speeds for
  ``C q̇`` and once with gravity alone for ``G``;
- ``M``: column ``i`` is the composite body beyond joint ``i`` moving along its axis,
  carried up to each ancestor ``j`` and projected on joint ``j``'s axis;
- a variable is made only for a non-trivial expression, ``cos²`` or ``sin²`` of a joint
  is replaced by ``1 − sin²`` / ``1 − cos²`` where that shortens it, ``sympy.cse`` then
  shares what is still repeated, and copies (``a = b``) are substituted away;
- mimic joints: every body moves with ``theta = S q + offset``; the equations of the bodies
  are mapped with ``M = Sᵀ M_full S``, ``C q̇ = Sᵀ (C q̇)_full``, ``G = Sᵀ G_full``;
- with ``keep_params`` masses, centres of mass, inertias, joint offsets and gravity are
  symbols (:class:`robodyn.reference.symbolic.Parameters`).

No Pinocchio here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import sympy as sp

from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, axis_rotation, body_coordinates, exact_matrix, joint_symbols


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


def trivial(expr: sp.Expr) -> bool:
    """Whether an expression is not worth a variable: a number, a symbol, or number × symbol."""
    return bool(
        expr.is_Number
        or expr.is_Symbol
        or (expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number and expr.args[1].is_Symbol)
    )


class _Program:
    """Collects assignments; a variable is made only for a non-trivial expression."""

    def __init__(self) -> None:
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []
        self.pairs: list[tuple[sp.Symbol, sp.Symbol]] = []  # (cos, sin) of a joint
        self._counter = 0

    def pythagoras(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` expanded, with ``c² = 1 − s²`` (or ``s² = 1 − c²``) of each joint where shorter."""
        expr = sp.expand(expr)
        for c, s in self.pairs:
            if not expr.has(c) or not expr.has(s):
                continue
            options = [expr, sp.expand(expr.subs(c**2, 1 - s**2)), sp.expand(expr.subs(s**2, 1 - c**2))]
            expr = min(options, key=sp.count_ops)
        return expr

    def let(self, expr: sp.Expr, prefix: str = "x") -> sp.Expr:
        expr = self.pythagoras(expr)
        if trivial(expr):
            return expr
        self._counter += 1
        symbol = sp.Symbol(f"{prefix}{self._counter}", real=True)
        self.assignments.append((symbol, expr))
        return symbol

    def vector(self, values, prefix: str) -> sp.Matrix:
        return sp.Matrix([self.let(v, prefix) for v in values])

    def matrix(self, matrix: sp.Matrix, prefix: str) -> sp.Matrix:
        return sp.Matrix(matrix.rows, matrix.cols, lambda i, j: self.let(matrix[i, j], prefix))


def _shared(equations: CompactDynamics) -> CompactDynamics:
    """Share repeated subexpressions (``sympy.cse``) and keep only what the outputs need,
    in dependency order."""
    names = [name for name, _ in equations.assignments]
    outputs = [*equations.M, *equations.Cv, *equations.G]
    extra, reduced = sp.cse(
        [expr for _, expr in equations.assignments] + outputs, symbols=sp.numbered_symbols("t", real=True), order="none"
    )
    definitions = dict(extra)
    definitions.update(zip(names, reduced[: len(names)], strict=True))
    outputs = reduced[len(names) :]
    n = len(equations.q)
    M = sp.Matrix(n, n, outputs[: n * n])
    Cv = sp.Matrix(outputs[n * n : n * n + n])
    G = sp.Matrix(outputs[n * n + n :])
    return replace(equations, assignments=_in_order(definitions, outputs), M=M, Cv=Cv, G=G)


def _reuse_products(equations: CompactDynamics) -> CompactDynamics:
    """Where a product ``t = a*b`` is assigned, later products containing ``a*b`` use ``t``,
    and each assignment is collected on a symbol where that saves operations."""
    pairs: dict[frozenset, sp.Symbol] = {}

    def reuse(expr: sp.Expr) -> sp.Expr:
        def fold(mul: sp.Expr) -> sp.Expr:
            factors = list(mul.args)
            changed = True
            while changed:
                changed = False
                symbols = [f for f in factors if f.is_Symbol]
                for i, a in enumerate(symbols):
                    for b in symbols[i + 1 :]:
                        t = pairs.get(frozenset((a, b)))
                        if t is not None:
                            factors.remove(a)
                            factors.remove(b)
                            factors.append(t)
                            changed = True
                            break
                    if changed:
                        break
            return sp.Mul(*factors)

        return expr.replace(lambda e: e.is_Mul and len(e.args) > 2, fold) if pairs else expr

    def collected(expr: sp.Expr) -> sp.Expr:
        if not expr.is_Add:
            return expr
        best = expr
        for symbol in sorted(expr.free_symbols, key=str):
            candidate = sp.collect(best, symbol)
            if sp.count_ops(candidate) < sp.count_ops(best):
                best = candidate
        return best

    assignments = []
    for symbol, expr in equations.assignments:
        expr = collected(reuse(expr))
        assignments.append((symbol, expr))
        if expr.is_Mul and len(expr.args) == 2 and all(a.is_Symbol for a in expr.args):
            pairs[frozenset(expr.args)] = symbol
    return replace(
        equations,
        assignments=assignments,
        M=equations.M.applyfunc(lambda e: collected(reuse(e))),
        Cv=equations.Cv.applyfunc(lambda e: collected(reuse(e))),
        G=equations.G.applyfunc(lambda e: collected(reuse(e))),
    )


def _without_copies(equations: CompactDynamics) -> CompactDynamics:
    """Substitute away assignments of a bare symbol or number (``a = b``) and repeats of an
    expression already assigned."""
    copies: dict[sp.Symbol, sp.Expr] = {}
    seen: dict[sp.Expr, sp.Symbol] = {}
    kept = []
    for symbol, expr in equations.assignments:
        expr = expr.xreplace(copies)
        if expr.is_Symbol or expr.is_Number:
            copies[symbol] = expr
        elif expr in seen:
            copies[symbol] = seen[expr]
        else:
            seen[expr] = symbol
            kept.append((symbol, expr))
    return replace(
        equations,
        assignments=kept,
        M=equations.M.xreplace(copies),
        Cv=equations.Cv.xreplace(copies),
        G=equations.G.xreplace(copies),
    )


def _in_order(definitions: dict[sp.Symbol, sp.Expr], outputs: list[sp.Expr]) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The definitions the outputs depend on, each after everything it uses."""
    ordered: list[tuple[sp.Symbol, sp.Expr]] = []
    state: dict[sp.Symbol, int] = {}  # 1: in progress, 2: done
    roots = sorted({s for e in outputs for s in e.free_symbols if s in definitions}, key=str)
    for root in roots:
        stack = [(root, False)]
        while stack:
            symbol, expanded = stack.pop()
            if state.get(symbol) == 2:
                continue
            if expanded:
                state[symbol] = 2
                ordered.append((symbol, definitions[symbol]))
                continue
            state[symbol] = 1
            stack.append((symbol, True))
            for dependency in definitions[symbol].free_symbols:
                if dependency in definitions and state.get(dependency) != 2:
                    stack.append((dependency, False))
    return ordered


def derive_compact(
    robot: ReferenceRobot,
    *,
    snap: float = 1e-8,
    cse: bool = True,
    keep_params: bool = False,
    symbols: tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]] | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> CompactDynamics:
    """Derive the compact (intermediate-variable) equations of a reference robot.

    Args:
        robot: From :func:`robodyn.reference.load` (mimic joints included).
        snap: Tolerance for exact rotation and axis entries.
        cse: Share repeated subexpressions with ``sympy.cse`` at the end.
        keep_params: Keep masses, centres of mass, inertias, joint offsets and gravity as
            symbols (see :class:`robodyn.reference.symbolic.Parameters`).
        symbols: ``(q, qd, qdd)`` to use instead of the reference's joint symbols.
        progress: Called as ``progress(stage, done, total)``.
    """
    tree = robot.tree
    q, qd, qdd = symbols or joint_symbols(robot.joint_names)
    theta, theta_dot = body_coordinates(robot, q, qd)
    params = Parameters(keep_params)
    program = _Program()
    bodies = tree.bodies
    count = len(bodies)
    zero = sp.zeros(3, 1)
    # Every entry is set (parents first) before it is read.
    R: list[sp.Matrix] = [zero] * count  # parent frame <- body frame
    t: list[sp.Matrix] = [zero] * count  # body origin in the parent frame
    axis: list[sp.Matrix] = [zero] * count  # joint axis in the body frame
    w, dw, acc = ([zero] * count for _ in range(3))  # angular velocity, its bias rate, origin's bias acceleration
    gacc = [zero] * count  # the acceleration gravity amounts to, in the body frame
    gravity = -params.gravity(robot.gravity_vector)  # the base "accelerates upwards"
    for b, body in enumerate(bodies):
        if progress:
            progress("kinematics", b, count)
        parent = body.parent
        axis[b] = exact_matrix(body.axis[:, None], snap)
        rotation = exact_matrix(body.origin[:3, :3], snap)
        translation = params.vector(body.origin[:3, 3], "d", body.joint)
        if body.revolute:
            c = program.let(sp.cos(theta[b]), f"c{b + 1}_")
            s = program.let(sp.sin(theta[b]), f"s{b + 1}_")
            if c.is_Symbol and s.is_Symbol:
                program.pairs.append((c, s))
            R[b] = program.matrix(rotation * axis_rotation(axis[b], c, s), f"R{b + 1}_")
            t[b] = translation
        else:
            R[b] = rotation
            t[b] = program.vector(translation + rotation * axis[b] * theta[b], f"t{b + 1}_")
        Rt = R[b].T
        w_par = zero if parent < 0 else w[parent]
        dw_par = zero if parent < 0 else dw[parent]
        a_par = zero if parent < 0 else acc[parent]
        g_par = gravity if parent < 0 else gacc[parent]
        w_in = program.vector(Rt * w_par, f"wi{b + 1}_")
        gacc[b] = program.vector(Rt * g_par, f"g{b + 1}_")
        origin_acc = a_par + dw_par.cross(t[b]) + w_par.cross(w_par.cross(t[b]))
        acc_b = Rt * origin_acc
        if body.revolute:
            w[b] = program.vector(w_in + axis[b] * theta_dot[b], f"w{b + 1}_")
            dw[b] = program.vector(Rt * dw_par + w_in.cross(axis[b] * theta_dot[b]), f"dw{b + 1}_")
        else:
            w[b] = w_in
            dw[b] = program.vector(Rt * dw_par, f"dw{b + 1}_")
            acc_b = acc_b + 2 * w_in.cross(axis[b] * theta_dot[b])
        acc[b] = program.vector(acc_b, f"a{b + 1}_")

    # Backward: forces and moments (about each body's origin) of the subtrees, for C q̇ and
    # for G; composite inertias (about each body's origin) for M.
    force, moment = [zero] * count, [zero] * count
    gforce, gmoment = [zero] * count, [zero] * count
    c_mass = [sp.Integer(0)] * count
    c_first = [zero] * count
    c_inertia = [sp.zeros(3, 3)] * count
    for b in reversed(range(count)):
        body = bodies[b]
        if progress:
            progress("Lagrangian", count - b, count)
        if body.mass != 0 or body.inertia.any():
            mass = params.symbol(body.mass, "m", body.link)
            com = params.vector(body.com, "c", body.link)
            inertia = params.inertia(body.inertia, body.link)
            com_acc = acc[b] + dw[b].cross(com) + w[b].cross(w[b].cross(com))
            f = program.vector(mass * com_acc, f"f{b + 1}_")
            n = inertia * dw[b] + w[b].cross(inertia * w[b]) + com.cross(f)
            force[b] = force[b] + f
            moment[b] = moment[b] + n
            fg = mass * gacc[b]
            gforce[b] = gforce[b] + fg
            gmoment[b] = gmoment[b] + com.cross(fg)
            first = mass * com
            c_mass[b] = c_mass[b] + mass
            c_first[b] = c_first[b] + first
            c_inertia[b] = c_inertia[b] + inertia + mass * ((com.T * com)[0] * sp.eye(3) - com * com.T)
        force[b], moment[b] = program.vector(force[b], f"F{b + 1}_"), program.vector(moment[b], f"N{b + 1}_")
        gforce[b], gmoment[b] = program.vector(gforce[b], f"FG{b + 1}_"), program.vector(gmoment[b], f"NG{b + 1}_")
        c_first[b] = program.vector(c_first[b], f"h{b + 1}_")
        c_inertia[b] = program.matrix(c_inertia[b], f"I{b + 1}_")
        parent = body.parent
        if parent >= 0:
            Rf, Rg = R[b] * force[b], R[b] * gforce[b]
            force[parent] = force[parent] + Rf
            moment[parent] = moment[parent] + R[b] * moment[b] + t[b].cross(Rf)
            gforce[parent] = gforce[parent] + Rg
            gmoment[parent] = gmoment[parent] + R[b] * gmoment[b] + t[b].cross(Rg)
            # The child's composite, moved to the parent's origin.
            h = R[b] * c_first[b]
            moved = R[b] * c_inertia[b] * R[b].T
            shift = c_mass[b] * ((t[b].T * t[b])[0] * sp.eye(3) - t[b] * t[b].T)
            cross = 2 * (t[b].T * h)[0] * sp.eye(3) - t[b] * h.T - h * t[b].T
            c_mass[parent] = c_mass[parent] + c_mass[b]
            c_first[parent] = c_first[parent] + h + c_mass[b] * t[b]
            c_inertia[parent] = c_inertia[parent] + moved + shift + cross

    def project(b: int, n: sp.Matrix, f: sp.Matrix) -> sp.Expr:
        return (axis[b].T * n)[0] if bodies[b].revolute else (axis[b].T * f)[0]

    M = sp.zeros(count, count)
    Cv = sp.zeros(count, 1)
    G = sp.zeros(count, 1)
    for i in range(count):
        Cv[i] = project(i, moment[i], force[i])
        G[i] = project(i, gmoment[i], gforce[i])
        # Column i of M: the composite body i moving along joint i's axis, carried up.
        if bodies[i].revolute:
            n, f = c_inertia[i] * axis[i], axis[i].cross(c_first[i])
        else:
            n, f = c_first[i].cross(axis[i]), c_mass[i] * axis[i]
        n, f = program.vector(n, f"Mn{i + 1}_"), program.vector(f, f"Mf{i + 1}_")
        j = i
        while j >= 0:
            M[i, j] = M[j, i] = project(j, n, f)
            parent = bodies[j].parent
            if parent < 0:
                break
            f_up = R[j] * f
            n, f = (
                program.vector(R[j] * n + t[j].cross(f_up), f"Mn{i + 1}_{parent + 1}_"),
                program.vector(f_up, f"Mf{i + 1}_{parent + 1}_"),
            )
            j = parent
    selection = exact_matrix(tree.selection, 0.0)
    if selection != sp.eye(count):  # mimic joints: tau = Sᵀ tau_full, theta'' = S q''
        M, Cv, G = selection.T * M * selection, selection.T * Cv, selection.T * G
    equations = CompactDynamics(
        q,
        qd,
        qdd,
        program.assignments,
        M.applyfunc(program.pythagoras),
        Cv.applyfunc(program.pythagoras),
        G.applyfunc(program.pythagoras),
        params.values,
        params.labels,
    )
    if cse:
        if progress:
            progress("common subexpressions", 0, 1)
        equations = _reuse_products(_without_copies(_shared(equations)))
    return _without_copies(equations)
