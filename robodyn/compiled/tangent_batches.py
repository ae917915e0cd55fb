"""The batch forms of the derivative kernel: states in SIMD lanes (see :mod:`robodyn.compiled.tangents`).

``rdd_tau_derivatives2`` (two states, SSE2) and ``rdd<L>_tau_derivatives`` (``L`` states, one
per SIMD variant of the build) run the writer's lane-by-lane statements (each direction's
entry written out) on vectors of states: the same IEEE operations in the same order as the
single call's lane, so a batch row is bit for bit its single call.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import sympy as sp

from robodyn.equations.c_printer import c_number

if TYPE_CHECKING:
    from robodyn.compiled.tangents import TangentWriter

#: A scalar call left in a vector statement (the vector forms take none).
SCALAR_CALL = re.compile(r"(?<!\w)(?:rd_)?(?:cos|sin|sincos|pow)\(")
#: The writer's ``double s, c; rd_sincos(x, &s, &c);`` (a vector form replaces its start).
SINCOS = re.compile(r"^    double (\w+), (\w+); rd_sincos\(")
#: A lone ``rd_sin``/``rd_cos`` statement, for its vector form.
TRIG = re.compile(r"= rd_(cos|sin)\((\w+)\);$")


def pair_function(writer: TangentWriter, used: set[sp.Basic], results: list[tuple[str, int, str]]) -> list[str]:
    """``rdd_tau_derivatives2``: the same statements on two states, one a SIMD lane
    (GCC/Clang vector extension; the same IEEE operations, so bit-identical results).

    Args:
        writer: The tangent writer whose scalar statements (:attr:`TangentWriter.lines`) are
            vectorised.
        used: The program's symbols the statements read (the coordinates loaded per lane).
        results: ``(array, index, C value)`` of every output entry: ``array`` ``"dq"`` or
            ``"dv"`` (∂tau/∂q, ∂tau/∂v), ``index`` ``j * nv + k`` (row j, column k, row-major).
    """
    body = [
        TRIG.sub(r"= rdd_\1_2(\2);", SINCOS.sub(r"    rdd_v2 \1, \2; rdd_sincos_2(", line)).replace(
            "const double ", "const rdd_v2 "
        )
        for line in writer.lines
    ]
    if any(SCALAR_CALL.search(line) for line in body):
        return ["#define RDD_PAIRS 0", ""]
    lanes = zip(writer._coordinates(used, "0"), writer._coordinates(used, "1"), strict=True)
    head = [
        f"{one.split(' = ')[0].replace('double', 'rdd_v2')} = {{{one.split(' = ')[1][:-1]}, {two.split(' = ')[1][:-1]}}};"
        for one, two in lanes
    ]
    tail = []
    for out, index, value in results:
        try:  # a constant: the same in both lanes
            tail.append(f"    {out}0[{index}] = {out}1[{index}] = {c_number(float(value))};")
        except ValueError:
            tail.append(f"    {{ const rdd_v2 o = {value}; {out}0[{index}] = o[0]; {out}1[{index}] = o[1]; }}")
    return [
        "#define RDD_PAIRS 1",
        "typedef double rdd_v2 __attribute__((vector_size(16)));",
        "static inline rdd_v2 rdd_cos_2(rdd_v2 x) { const rdd_v2 r = {rd_cos(x[0]), rd_cos(x[1])}; return r; }",
        "static inline rdd_v2 rdd_sin_2(rdd_v2 x) { const rdd_v2 r = {rd_sin(x[0]), rd_sin(x[1])}; return r; }",
        "static inline void rdd_sincos_2(rdd_v2 x, rdd_v2 *s, rdd_v2 *c) {",
        "    for (int l = 0; l < 2; ++l) { double a, b; rd_sincos(x[l], &a, &b); (*s)[l] = a; (*c)[l] = b; }",
        "}",
        "static void rdd_tau_derivatives2(const double *q0, const double *v0, const double *a0, const double *q1,",
        "                                 const double *v1, const double *a1, double *dq0, double *dv0, double *dq1, double *dv1) {",
        *head,
        *body,
        *tail,
        "}",
        "",
    ]


def block_functions(writer: TangentWriter, used: set[sp.Basic], results: list[tuple[str, int, str]]) -> list[str]:
    """``rdd<L>_tau_derivatives``: the same statements on ``L`` states at once, one a lane
    of a vector of the instruction set of each of :attr:`TangentWriter.variants` (``(name,
    L, GCC target)``, :data:`robodyn.compiled.simd.VARIANTS`: SSE2, AVX2, AVX-512), compiled
    with its ``target`` attribute; ``cos``/``sin`` the SIMD dynamics' (``rds<L>_sin``: the
    single call's ``rd_sin`` on every lane). ``RDD_BLOCKS`` names the variants for
    ``derivatives.c``'s blocks and dispatch. Inputs: ``L`` rows; outputs: ``∂τ/∂q`` and
    ``∂τ/∂v`` as ``nv²`` vectors each (entry ``j nv + k`` of the ``L`` states in one), which
    the forward dynamics' solves take as they are.

    Args:
        writer: The tangent writer whose scalar statements (:attr:`TangentWriter.lines`) are
            vectorised.
        used: The program's symbols the statements read (the coordinates loaded per lane).
        results: ``(array, index, C value)`` of every output entry: ``array`` ``"dq"`` or
            ``"dv"`` (∂tau/∂q, ∂tau/∂v), ``index`` ``j * nv + k`` (row j, column k, row-major).
    """
    out: list[str] = []
    names: list[str] = []
    for name, lanes, target in writer.variants:
        vector, attribute = f"rdd{lanes}", f'__attribute__((target("{target}")))'
        body = [
            TRIG.sub(rf"= {vector}_\1(\2);", SINCOS.sub(rf"    {vector} \1, \2; {vector}_sincos(", line)).replace(
                "const double ", f"const {vector} "
            )
            for line in writer.lines
        ]
        if any(SCALAR_CALL.search(line) for line in body):
            return ["#define RDD_BLOCKS(X)", ""]
        lane_values = [writer._coordinates(used, str(lane)) for lane in range(lanes)]
        head = []
        for i, first in enumerate(lane_values[0]):
            values = ", ".join(lane_values[lane][i].split(" = ", 1)[1][:-1] for lane in range(lanes))
            head.append(f"    const {vector} {first.split(' = ')[0].split()[-1]} = {{{values}}};")
        tail = []
        for array, index, value in results:
            try:  # a constant: the same in every lane
                constant = c_number(float(value))
                tail.append(f"    {array}[{index}] = ({vector}){{{', '.join([constant] * lanes)}}};")
            except ValueError:
                tail.append(f"    {array}[{index}] = {value};")
        pointers = [
            f"    const double *q{lane} = q[{lane}], *v{lane} = v[{lane}], *a{lane} = a[{lane}];" for lane in range(lanes)
        ]
        inline = f"static inline __attribute__((always_inline)) {attribute}"
        lane_loop = f"{vector} r; for (int l = 0; l < {lanes}; ++l) r[l] ="
        out += [
            f"typedef double {vector} __attribute__((vector_size({8 * lanes})));",
            "#ifdef RD_SIMD",  # the SIMD dynamics' sin and cos on vectors: rd_sin's operations on every lane
            f"{inline} {vector} {vector}_cos({vector} x) {{ return rds{lanes}_cos(x); }}",
            f"{inline} {vector} {vector}_sin({vector} x) {{ return rds{lanes}_sin(x); }}",
            f"{inline} void {vector}_sincos({vector} x, {vector} *s, {vector} *c) {{ rds{lanes}_sincos(x, s, c); }}",
            "#else",
            f"{inline} {vector} {vector}_cos({vector} x) {{ {lane_loop} rd_cos(x[l]); return r; }}",
            f"{inline} {vector} {vector}_sin({vector} x) {{ {lane_loop} rd_sin(x[l]); return r; }}",
            f"{inline} void {vector}_sincos({vector} x, {vector} *s, {vector} *c) {{",
            f"    for (int l = 0; l < {lanes}; ++l) {{ double a, b; rd_sincos(x[l], &a, &b); (*s)[l] = a; (*c)[l] = b; }}",
            "}",
            "#endif",
            f"static {attribute} void {vector}_tau_derivatives(const double *const *q, const double *const *v,",
            f"        const double *const *a, {vector} *dq, {vector} *dv) {{",
            *pointers,
            *head,
            *body,
            *tail,
            "}",
            "",
        ]
        vzeroupper = "__builtin_ia32_vzeroupper();" if lanes > 2 else ""
        names.append(f'X({vector}, {lanes}, "{name}", "{target}", {attribute}, rds{lanes}, {vzeroupper})')
    if not out:
        return ["#define RDD_BLOCKS(X)", ""]
    guard = "#if defined(__x86_64__) && defined(__GNUC__)"
    return [guard, *out, f"#define RDD_BLOCKS(X) {' '.join(names)}", "#else", "#define RDD_BLOCKS(X)", "#endif", ""]
