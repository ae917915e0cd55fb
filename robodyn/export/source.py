"""A robot's exported functions as a standalone Python module (CasADi or JAX).

One module text for both backends: the programs of :mod:`robodyn.export.programs` printed
as Python functions of lists of scalars (the expressions through the one C printer,
:class:`robodyn.equations.c_printer.CPrinter`, whose output — sums, products, ``(a/b)``,
``(x*x)``, ``pow``, ``sin``, ``cos`` — is Python too), the projections onto the robot's
coordinates and the tree LDLᵀ of the compiled engine (``core.c``'s ``RD_LDL_DEFINE``: the
same operations, unrolled, on symbolic values; parents before children, no fill-in), then a
backend tail that builds CasADi SX functions or plain ``jax.numpy`` functions.
:func:`robodyn.export.casadi_functions` and :func:`robodyn.export.jax_functions` run exactly
this text, so the module a user writes and the functions the library gives are the same.

No name from the URDF reaches the code: coordinates are ``th[b]``, ``q[i]``, intermediate
variables ``tN``/``rN``/``kN``, kept parameters ``p[i]``; names appear only in the docstring
(through :func:`robodyn.common.text.comment_text`) and as ``ascii()`` literals.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Literal

import sympy as sp

from robodyn.common.text import comment_text
from robodyn.equations.c_printer import CPrinter
from robodyn.equations.program import Program, needed
from robodyn.export.factoring import factored
from robodyn.export.programs import ExportPrograms

Backend = Literal["casadi", "jax"]

_HELPERS = '''

M_PI = 3.141592653589793
M_SQRT2 = 1.4142135623730951
M_SQRT1_2 = 0.7071067811865476


def sqrt(x):
    return x**0.5


def _sum(terms):
    """The sum of c x over (c, x) pairs: unit coefficients and zero terms left out; 0.0 for none."""
    total = None
    for c, x in terms:
        if isinstance(x, float) and x == 0.0:
            continue
        term = x if c == 1.0 else c * x
        total = term if total is None else total + term
    return 0.0 if total is None else total


def _bodies(x, shift):
    """The bodies' coordinates theta = S x (+ offset when shift)."""
    out = []
    for b in range(_NB):
        value = _sum((s, x[j]) for j, s in _ROWS[b])
        out.append(value + _OFFSET[b] if shift and _OFFSET[b] != 0.0 else value)
    return out


def _joints(xb):
    """S^T xb: a vector of the bodies to the robot's coordinates."""
    return [_sum((s, xb[b]) for b, s in _COLUMNS[j]) for j in range(NV)]


def _joints_matrix(mb):
    """S^T M S (mb row-major over the bodies), as rows."""
    M = [[0.0] * NV for _ in range(NV)]
    for j in range(NV):
        for k in range(j + 1):
            terms = [(sj * sk, mb[b * _NB + c]) for b, sj in _COLUMNS[j] for c, sk in _COLUMNS[k]]
            M[j][k] = M[k][j] = _sum(terms)
    return M


def _ldl_solve(M, b):
    """M x = b by M = L^T D L along the tree (robodyn.compiled's core.c, unrolled)."""
    M, b, parent = [list(row) for row in M], list(b), _PARENTS
    for k in reversed(range(NV)):
        d, i = M[k][k], parent[k]
        while i >= 0:
            x, j = M[k][i] / d, i
            while j >= 0:
                M[i][j] = M[i][j] - M[k][j] * x
                j = parent[j]
            M[k][i], i = x, parent[i]
    for i in reversed(range(NV)):
        j = parent[i]
        while j >= 0:
            b[j], j = b[j] - M[i][j] * b[i], parent[j]
    b = [b[i] / M[i][i] for i in range(NV)]
    for i in range(NV):
        j = parent[i]
        while j >= 0:
            b[i], j = b[i] - M[i][j] * b[j], parent[j]
    return b


def _mass(q, p):
    return _joints_matrix(_mass_bodies(_bodies(q, True), p))


def _nle(q, v, p):
    return _joints(_nle_bodies(_bodies(q, True), _bodies(v, False), p))


def _gravity(q, p):
    return _joints(_gravity_bodies(_bodies(q, True), p))


def _tau(q, v, a, p):
    return _joints(_tau_bodies(_bodies(q, True), _bodies(v, False), _bodies(a, False), p))


def _forward(q, v, tau, p):
    h = _nle(q, v, p)
    return _ldl_solve(_mass(q, p), [tau[i] - h[i] for i in range(NV)])


def _frame(k, q, p):
    position, jb = _FRAMES[k](_bodies(q, True), p)
    jacobian = [[_sum((s, jb[r * _NB + b]) for b, s in _COLUMNS[j]) for j in range(NV)] for r in range(6)]
    return position, jacobian
'''

_CASADI = '''

def _entries(x):
    return [x[i] for i in range(x.numel())]


def _column(xs):
    return ca.vertcat(*[ca.SX(x) for x in xs])


def _matrix(rows):
    return ca.vertcat(*[ca.horzcat(*[ca.SX(x) for x in row]) for row in rows])


def functions():
    """The robot's functions as casadi.Function (SX), by name.

    inverse_dynamics(q, v, a) -> tau, mass_matrix(q) -> M, nonlinear_effects(q, v) -> C v + G,
    gravity(q) -> G, forward_dynamics(q, v, tau) -> a (tree-structured LDL^T of M), and for
    every frame of FRAME_NAMES "frame_position:<frame>"(q) -> (3, 1) in [m] and
    "frame_jacobian:<frame>"(q) -> (6, nv), linear rows then angular, world-aligned. With
    kept parameters every function takes PARAMETER_NAMES' values as a last input p.
    """
    q, v, a, tau = (ca.SX.sym(name, NV) for name in ("q", "v", "a", "tau"))
    p = ca.SX.sym("p", len(PARAMETER_NAMES))
    qs, vs, accs, taus, ps = (_entries(x) for x in (q, v, a, tau, p))
    extra, extra_names = ([p], ["p"]) if PARAMETER_NAMES else ([], [])

    def function(name, inputs, names, output, output_name):
        options = {"cse": True}  # one node per distinct expression (sin, cos shared by M and C v + G)
        return ca.Function(name, [*inputs, *extra], [output], [*names, *extra_names], [output_name], options)

    result = {
        "inverse_dynamics": function("inverse_dynamics", [q, v, a], ["q", "v", "a"], _column(_tau(qs, vs, accs, ps)), "tau"),
        "mass_matrix": function("mass_matrix", [q], ["q"], _matrix(_mass(qs, ps)), "M"),
        "nonlinear_effects": function("nonlinear_effects", [q, v], ["q", "v"], _column(_nle(qs, vs, ps)), "nle"),
        "gravity": function("gravity", [q], ["q"], _column(_gravity(qs, ps)), "G"),
        "forward_dynamics": function(
            "forward_dynamics", [q, v, tau], ["q", "v", "tau"], _column(_forward(qs, vs, taus, ps)), "a"
        ),
    }
    for k, frame in enumerate(FRAME_NAMES):
        position, jacobian = _frame(k, qs, ps)
        result["frame_position:" + frame] = function(f"frame_position_{k}", [q], ["q"], _column(position), "position")
        result["frame_jacobian:" + frame] = function(f"frame_jacobian_{k}", [q], ["q"], _matrix(jacobian), "J")
    return result
'''

_JAX = '''

def _entries(x):
    x = jnp.asarray(x, dtype=jnp.float64)
    return [x[i] for i in range(x.shape[0])]


def _vector(xs):
    return jnp.stack([jnp.asarray(x, dtype=jnp.float64) for x in xs])


def _matrix(rows):
    return jnp.stack([_vector(row) for row in rows])


def _function(compute, output):
    """compute(*states, p) on lists of scalars, as a function of arrays (p last when kept)."""
    if PARAMETER_NAMES:

        def function(*args):
            *states, p = args
            return output(compute(*[_entries(x) for x in states], _entries(p)))

    else:

        def function(*args):
            return output(compute(*[_entries(x) for x in args], ()))

    return function


def functions():
    """The robot's functions as pure jax.numpy functions of one state (jit, vmap, grad).

    inverse_dynamics(q, v, a) -> tau, mass_matrix(q) -> M, nonlinear_effects(q, v) -> C v + G,
    gravity(q) -> G, forward_dynamics(q, v, tau) -> a (tree-structured LDL^T of M), and for
    every frame of FRAME_NAMES "frame_position:<frame>"(q) -> (3,) in [m] and
    "frame_jacobian:<frame>"(q) -> (6, nv), linear rows then angular, world-aligned. With
    kept parameters every function takes PARAMETER_NAMES' values as a last argument p.
    Float64 only: needs jax.config.update("jax_enable_x64", True) first.
    """
    if not jax.config.jax_enable_x64:
        raise RuntimeError("these functions compute in float64: call jax.config.update('jax_enable_x64', True) first")
    result = {
        "inverse_dynamics": _function(_tau, _vector),
        "mass_matrix": _function(_mass, _matrix),
        "nonlinear_effects": _function(_nle, _vector),
        "gravity": _function(_gravity, _vector),
        "forward_dynamics": _function(_forward, _vector),
    }
    for k, frame in enumerate(FRAME_NAMES):
        result["frame_position:" + frame] = _function(lambda q, p, k=k: _frame(k, q, p)[0], _vector)
        result["frame_jacobian:" + frame] = _function(lambda q, p, k=k: _frame(k, q, p)[1], _matrix)
    return result
'''

_IMPORTS = {
    "casadi": "import casadi as ca\n\nsin, cos = ca.sin, ca.cos",
    "jax": "import jax\nimport jax.numpy as jnp\n\nsin, cos = jnp.sin, jnp.cos",
}
_TAILS = {"casadi": _CASADI, "jax": _JAX}


def _printer(program: Program, prefix: str, programs: ExportPrograms, parameters: dict[sp.Symbol, str]) -> CPrinter:
    """A printer of one program: assignments ``<prefix>N``, coordinates ``th[b]``/``thd[b]``/
    ``thdd[b]``, kept parameters ``p[i]``."""
    names = {symbol: f"{prefix}{index}" for index, (symbol, _) in enumerate(program.assignments)}
    for symbols, local in zip(programs.symbols, ("th", "thd", "thdd"), strict=True):
        names.update({symbol: f"{local}[{b}]" for b, symbol in enumerate(symbols)})
    names.update(parameters)
    return CPrinter(names)


def _function(
    printer: CPrinter, program: Program, head: str, outputs: Sequence[sp.Expr], body: Sequence[str], result: str
) -> list[str]:
    """``def <head>:`` with the assignments ``outputs`` need, then ``body`` and ``return result``."""
    lines = [f"def {head}:"]
    lines += [f"    {printer.names[s]} = {printer.expression(e)}" for s, e in needed(program.assignments, outputs)]
    return [*lines, *body, f"    return {result}", "", ""]


def _mass_lines(printer: CPrinter, M: Sequence[sp.Expr], count: int) -> list[str]:
    """``mb``: the bodies' mass matrix, row-major, each entry below the diagonal printed once."""
    lines = [f"    mb = [0.0] * {count * count}"]
    for b in range(count):
        for c in range(b + 1):
            if M[b * count + c] != 0:
                lines.append(f"    mb[{b * count + c}] = mb[{c * count + b}] = {printer.expression(M[b * count + c])}")
    return lines


def _vector_line(printer: CPrinter, name: str, entries: Sequence[sp.Expr]) -> str:
    return f"    {name} = [{', '.join(printer.expression(e) for e in entries)}]"


def _dynamics(programs: ExportPrograms, parameters: dict[sp.Symbol, str]) -> list[str]:
    """``_mass_bodies``, ``_gravity_bodies`` (compact program), ``_nle_bodies``, ``_tau_bodies``
    (Newton–Euler programs)."""
    program, count = programs.dynamics, len(programs.offset)
    printer = _printer(program, "t", programs, parameters)
    M, G = list(program.outputs["M"]), list(program.outputs["G"])
    lower = [M[b * count + c] for b in range(count) for c in range(b + 1)]
    lines = _function(printer, program, "_mass_bodies(th, p)", lower, _mass_lines(printer, M, count), "mb")
    lines += _function(printer, program, "_gravity_bodies(th, p)", G, [_vector_line(printer, "gb", G)], "gb")
    for head, ne, prefix in (
        ("_nle_bodies(th, thd, p)", programs.nle, "h"),
        ("_tau_bodies(th, thd, thdd, p)", programs.tau, "r"),
    ):
        tau, ne_printer = list(ne.outputs["tau"]), _printer(ne, prefix, programs, parameters)
        lines += _function(ne_printer, ne, head, tau, [_vector_line(ne_printer, "tb", tau)], "tb")
    return lines


def _frames(programs: ExportPrograms, parameters: dict[sp.Symbol, str]) -> list[str]:
    """``_frame_<k>(th, p)`` -> (position, Jacobian row-major over the bodies) per frame."""
    program = programs.frames
    printer = _printer(program, "k", programs, parameters)
    lines: list[str] = []
    for k in range(len(programs.frame_names)):
        position, jacobian = list(program.outputs[f"p{k}"]), list(program.outputs[f"J{k}"])
        body = [_vector_line(printer, "position", position), _vector_line(printer, "jacobian", jacobian)]
        lines += _function(printer, program, f"_frame_{k}(th, p)", position + jacobian, body, "position, jacobian")
    count = len(programs.frame_names)
    return [*lines, f"_FRAMES = ({''.join(f'_frame_{k}, ' for k in range(count))})", ""]


def _constants(programs: ExportPrograms) -> list[str]:
    """Names (``ascii()`` literals), sizes, the map ``theta = S q + offset`` and the tree."""
    S = programs.selection
    count, nv = S.shape
    rows = [tuple((j, float(S[b, j])) for j in range(nv) if S[b, j] != 0) for b in range(count)]
    columns = [tuple((b, float(S[b, j])) for b in range(count) if S[b, j] != 0) for j in range(nv)]
    return [
        f"JOINT_NAMES = [{', '.join(ascii(name) for name in programs.joint_names)}]",
        f"FRAME_NAMES = [{', '.join(ascii(name) for name in programs.frame_names)}]",
        f"PARAMETER_NAMES = [{', '.join(ascii(str(symbol)) for symbol in programs.parameters)}]",
        f"PARAMETER_VALUES = [{', '.join(repr(float(value)) for value in programs.parameters.values())}]",
        f"NV = {nv}",
        f"_NB = {count}",
        f"_ROWS = {tuple(rows)!r}",
        f"_COLUMNS = {tuple(columns)!r}",
        f"_OFFSET = {tuple(float(x) for x in programs.offset)!r}",
        f"_PARENTS = {tuple(programs.parents)!r}",
    ]


def module_text(programs: ExportPrograms, backend: Backend) -> str:
    """The standalone module (imports only ``casadi``, or only ``jax``) whose
    ``functions()`` returns the robot's functions by name (see the tail's docstring).

    Args:
        programs: The robot's exported programs (:func:`robodyn.export.programs.export_programs`).
        backend: ``"casadi"`` or ``"jax"``: the only library the module imports.
    """
    parameters = {symbol: f"p[{index}]" for index, symbol in enumerate(programs.parameters)}
    # the dynamics printed with their sums' common factors out and negations folded
    programs = dataclasses.replace(
        programs, dynamics=factored(programs.dynamics), tau=factored(programs.tau), nle=factored(programs.nle)
    )
    library = {"casadi": "CasADi", "jax": "JAX"}[backend]
    header = [
        f'"""{library} functions of {comment_text(programs.robot)}, generated by robodyn from its URDF.',
        "",
        f"Joints, in the order of q, v, a, tau: {', '.join(comment_text(name) for name in programs.joint_names)}.",
        f"functions() returns them by name. SI units. Needs {backend} only.",
        '"""',
        "",
        _IMPORTS[backend],
        "",
    ]
    lines = [*header, *_constants(programs), _HELPERS, *_dynamics(programs, parameters), *_frames(programs, parameters)]
    return "\n".join(lines) + _TAILS[backend]
