"""The single call of the derivative kernel: its directions in SIMD lanes (see :mod:`robodyn.compiled.tangents`).

``rdd_tau_derivatives`` and ``rdd_fd_derivatives`` run the writer's vector statements in
chunks of an instruction set's width, compiled plainly (SSE2) and once per SIMD variant of
the build, the widest the CPU runs chosen at the first call (:data:`_DISPATCH`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import sympy as sp

if TYPE_CHECKING:
    from robodyn.compiled.tangents import Statement, TangentWriter


def single_functions(writer: TangentWriter, used: set[sp.Basic], stores: list[Statement]) -> list[str]:
    """``rdd_tau_derivatives`` and ``rdd_fd_derivatives`` (:data:`_SINGLE`): the vector
    statements in chunks of the instruction set's width, compiled plainly (2 lanes, SSE2)
    and once per SIMD variant of the build (its ``target``), the widest the CPU runs
    chosen at the first call; the single call's scalar part (``M``, the forward dynamics'
    ``M``, ``q̈`` and LDLᵀ: :data:`_SCALAR`) compiled for that variant's instruction set too.

    Args:
        writer: The tangent writer whose vector statements (:attr:`TangentWriter.vector_lines`)
            are printed, and its build's SIMD variants.
        used: The program's symbols the statements read (the coordinates loaded).
        stores: The single call's stores: ``(target, terms)``, ``Sᵀ`` times the bodies' tangents.
    """
    variants = [("plain", 2, "")] + [(name, lanes, target) for name, lanes, target in writer.variants if lanes > 2]
    lines = ["static int rdd_fd_start(const double *const *in, double *M, double *a); /* derivatives.c */"]
    for width in sorted({lanes for _, lanes, _ in variants}):
        lines += _vector_body(writer, used, stores, width)
    choice = []
    for name, lanes, target in variants:
        attribute = f'__attribute__((target("{target}")))' if target else ""
        text = (
            _SINGLE.replace("NAME", name)
            .replace("ATTR", attribute)
            .replace("VZEROUPPER", "" if not target else "__builtin_ia32_vzeroupper();")
        )
        text = text.replace("TYPE", f"rdd_w{lanes}").replace("CHUNKS", str(-(-writer.nv // lanes))).replace("WIDTH", str(lanes))
        if target:
            text += "\n" + _SCALAR.replace("NAME", name).replace("ATTR", attribute)
            text = f"#if defined(__x86_64__) && defined(__GNUC__)\n{text}\n#endif"
            choice.append(
                f'    if (__builtin_cpu_supports("{target}"))\n'
                f"        tau = rdd_tau_{name}, fd = rdd_fd_{name}, mass = rdd_mass_{name}, start = rdd_start_{name};"
            )
        lines.append(text)
    choose = ["#if defined(__x86_64__) && defined(__GNUC__)", "    __builtin_cpu_init();", *choice, "#endif"]
    return [*lines, _DISPATCH.replace("CHOOSE", "\n".join(choose if choice else [])), ""]


def _vector_body(writer: TangentWriter, used: set[sp.Basic], stores: list[Statement], width: int) -> list[str]:
    """``rdd_dirs_w<width>``: the single call's statements, each adjoint in chunks of
    ``width`` outputs (a chunk no lane of which can be non-zero is not computed), then the
    columns of ``∂τ/∂q`` and ``∂τ/∂v`` turned into rows ``bq``, ``bv`` (lane ``k``:
    ``∂τ_j/∂x_k``)."""
    vector, chunks = f"rdd_w{width}", -(-writer.nv // width)
    lines = [
        f"typedef double {vector} __attribute__((vector_size({8 * width})));",
        _SOLVE.replace("TYPE", vector).replace("CHUNKS", str(chunks)),
        f"static inline __attribute__((always_inline)) void rdd_dirs_w{width}("
        f"const double *q, const double *v, const double *a, {vector} (*bq)[{chunks}], {vector} (*bv)[{chunks}]) {{",
        *writer._coordinates(used),
    ]
    for item in [*writer.vector_lines, *stores]:
        if isinstance(item, str):
            lines.append(item)
            continue
        target, terms = item
        for c in range(chunks):
            lanes = range(c * width, (c + 1) * width)
            present = [(k, f, t) for k, f, t in terms if any(lane in t[2] for lane in lanes)]
            value = " + ".join(writer._vector_term(k, f, t, lanes, vector) for k, f, t in present) or f"({vector}){{0.0}}"
            if target.startswith("c"):  # column k of a group: c<group>[k]
                lines.append(f"    const {vector} {target.replace('[', '').replace(']', '')}_c{c} = {value};")
            elif present:
                lines.append(f"    const {vector} {target}_c{c} = {value};")
    n = writer.nv
    for group in ("q", "v"):  # rows from the columns, in registers (lanes past nv zero)
        for j in range(n):
            for c in range(chunks):
                entries = [
                    f"c{group}{k}_c{j // width}[{j % width}]" if k < n else "0.0" for k in range(c * width, (c + 1) * width)
                ]
                lines.append(f"    b{group}[{j}][{c}] = ({vector}){{{', '.join(entries)}}};")
    return [*lines, "}"]


#: ``b -> M⁻¹ b`` for direction vectors ``b`` (rows of ``CHUNKS`` ``TYPE``s), ``M`` factored:
#: derivatives.c's ``rdd_columns``' operations (a reciprocal a row), column ``c`` in lane ``c`` (the same bits).
_SOLVE = """static inline __attribute__((always_inline)) void rdd_apply_TYPE(const double *M, TYPE (*b)[CHUNKS]) {
    const int n = RD_NV;
    RD_UNROLL for (int i = n - 1; i >= 0; --i)
        RD_UNROLL for (int a = 0; a < rd_depth[i]; ++a) {
            const int j = rd_ancestor[i][a];
            RD_UNROLL for (int c = 0; c < CHUNKS; ++c) b[j][c] -= M[i * n + j] * b[i][c];
        }
    RD_UNROLL for (int i = 0; i < n; ++i) {
        const double r = 1.0 / M[i * n + i];
        RD_UNROLL for (int c = 0; c < CHUNKS; ++c) b[i][c] *= r;
    }
    RD_UNROLL for (int i = 0; i < n; ++i)
        RD_UNROLL for (int a = 0; a < rd_depth[i]; ++a) {
            const int j = rd_ancestor[i][a];
            RD_UNROLL for (int c = 0; c < CHUNKS; ++c) b[i][c] -= M[i * n + j] * b[j][c];
        }
}"""
#: One variant's functions: the direction vectors, then ``∂τ`` stored, or ``∂q̈ = −M⁻¹ ∂τ``
#: and ``M⁻¹`` (derivatives.c's ``rdd_fd_finish``: solved, then negated).
_SINGLE = """static ATTR void rdd_dirs_NAME(const double *q, const double *v, const double *a, TYPE (*bq)[CHUNKS],
                               TYPE (*bv)[CHUNKS]) {
    rdd_dirs_wWIDTH(q, v, a, bq, bv);
}
static ATTR void rdd_tau_NAME(const double *q, const double *v, const double *a, double *dq, double *dv) {
    TYPE bq[RD_NV][CHUNKS], bv[RD_NV][CHUNKS];
    rdd_dirs_NAME(q, v, a, bq, bv);
    RD_UNROLL for (int j = 0; j < RD_NV; ++j) RD_UNROLL for (int c = 0; c < CHUNKS; ++c) {
        const int size = 8 * (c + 1 < CHUNKS ? WIDTH : RD_NV - c * WIDTH);
        memcpy(dq + j * RD_NV + c * WIDTH, &bq[j][c], size);
        memcpy(dv + j * RD_NV + c * WIDTH, &bv[j][c], size);
    }
    VZEROUPPER
}
static ATTR void rdd_fd_NAME(const double *q, const double *v, const double *a, const double *M, double *dq,
                             double *dv, double *minv) {
    TYPE bq[RD_NV][CHUNKS], bv[RD_NV][CHUNKS], bi[RD_NV][CHUNKS];
    rdd_dirs_NAME(q, v, a, bq, bv);
    RD_UNROLL for (int j = 0; j < RD_NV; ++j) {
        RD_UNROLL for (int c = 0; c < CHUNKS; ++c) bi[j][c] = (TYPE){0.0};
        bi[j][j / WIDTH][j % WIDTH] = 1.0;
    }
    rdd_apply_TYPE(M, bq);
    rdd_apply_TYPE(M, bv);
    rdd_apply_TYPE(M, bi);
    RD_UNROLL for (int j = 0; j < RD_NV; ++j) RD_UNROLL for (int c = 0; c < CHUNKS; ++c) {
        const int size = 8 * (c + 1 < CHUNKS ? WIDTH : RD_NV - c * WIDTH);
        const TYPE nq = -bq[j][c], nv = -bv[j][c];
        memcpy(dq + j * RD_NV + c * WIDTH, &nq, size);
        memcpy(dv + j * RD_NV + c * WIDTH, &nv, size);
        memcpy(minv + j * RD_NV + c * WIDTH, &bi[j][c], size);
    }
    VZEROUPPER
}"""
#: A SIMD variant's copy of the single call's scalar part: the robot's ``rd_mass`` (``∂τ/∂q̈``)
#: and derivatives.c's ``rdd_fd_start`` (``rd_mass_nle``, ``q̈``, the LDLᵀ of ``M``) inlined
#: (``flatten``) into functions compiled for the variant's instruction set: the same IEEE
#: operations in the same order (no FMA: contraction is off), so the same bits, in its
#: three-operand forms and 32 registers (AVX-512, panda arm: ∂q̈ 2.07 -> 1.89 µs a call).
_SCALAR = """static ATTR __attribute__((flatten)) void rdd_mass_NAME(const double *q, double *M) { rd_mass(q, M); }
static ATTR __attribute__((flatten)) int rdd_start_NAME(const double *const *in, double *M, double *a) {
    return rdd_fd_start(in, M, a);
}"""
#: ``rdd_tau_derivatives`` (one state: ``∂τ/∂q``, ``∂τ/∂v``) and ``rdd_fd_derivatives`` (one
#: state at ``a = q̈`` with ``M`` factored: ``∂q̈/∂q``, ``∂q̈/∂v``, ``M⁻¹``), and the single
#: call's ``rdd_single_mass`` (``rd_mass``) and ``rdd_single_start`` (derivatives.c's
#: ``rdd_fd_start``), each the widest variant the CPU runs.
_DISPATCH = """typedef void (*rdd_tau_fn)(const double *, const double *, const double *, double *, double *);
typedef void (*rdd_fd_fn)(const double *, const double *, const double *, const double *, double *, double *, double *);
typedef void (*rdd_mass_fn)(const double *, double *);
typedef int (*rdd_start_fn)(const double *const *, double *, double *);
static rdd_tau_fn rdd_tau_current = NULL;
static rdd_fd_fn rdd_fd_current = NULL;
static rdd_mass_fn rdd_mass_current = NULL;
static rdd_start_fn rdd_start_current = NULL;
static void rdd_choose(void) {
    rdd_tau_fn tau = rdd_tau_plain;
    rdd_fd_fn fd = rdd_fd_plain;
    rdd_mass_fn mass = rd_mass;
    rdd_start_fn start = rdd_fd_start;
CHOOSE
    rdd_start_current = start;
    rdd_mass_current = mass;
    rdd_fd_current = fd;
    rdd_tau_current = tau;
}
static void rdd_single_mass(const double *q, double *M) {
    if (!rdd_mass_current) rdd_choose();
    rdd_mass_current(q, M);
}
static int rdd_single_start(const double *const *in, double *M, double *a) {
    if (!rdd_start_current) rdd_choose();
    return rdd_start_current(in, M, a);
}
static void rdd_tau_derivatives(const double *q, const double *v, const double *a, double *dq, double *dv) {
    if (!rdd_tau_current) rdd_choose();
    rdd_tau_current(q, v, a, dq, dv);
}
static void rdd_fd_derivatives(const double *q, const double *v, const double *a, const double *M, double *dq,
                               double *dv, double *minv) {
    if (!rdd_fd_current) rdd_choose();
    rdd_fd_current(q, v, a, M, dq, dv, minv);
}"""
