"""Batches several states per instruction: the robot's kernels on SIMD vectors of states.

:func:`vector_source` turns a robot's generated kernels (:mod:`robodyn.compiled.codegen`)
into vector kernels, one set per instruction set: the same statements on vectors of ``L``
doubles (GCC/Clang vector extension; ``L`` = 2 for SSE2, 4 for AVX2, 8 for AVX-512), each
set compiled for its instruction set with a ``target`` attribute, and ``simd.c`` wraps them
as blocks of ``L`` rows of a batch (structure of arrays: entry ``j`` of ``L`` states in one
vector). The C text comes from the one C printer
(:func:`robodyn.equations.c_printer.vector_lines`). ``runtime.c`` runs a batch block by
block on its threads and the remainder rows (a batch not a multiple of ``L``) through the
scalar kernels; forward dynamics factors ``L`` mass matrices at once (the tree's LDLᵀ is
the same for every state).

Every row is bit-for-bit the scalar kernel's result: the vector code does the same IEEE
operations in the same order (no fused multiply-add: the variants' targets leave FMA out
and contraction is off), and ``sin``/``cos`` are the kernels' own (``trig.c``, the macro
``RD_TRIG_DEFINE`` the kernels' text defines, instantiated here on the vector type: the
scalar ``rd_sin``'s operations on every lane at once, ``sin`` and ``cos`` of one argument
paired into one ``sincos``; libm's, lane by lane, only for a lane beyond ``|x| > 2^20``, as
the scalar does). With libm's ``sincos`` called lane by lane, five a state were ~680 of ur5's
~1 070 instructions with AVX2 (callgrind) and 70-80 % of the time with AVX-512. Forward
dynamics' LDLᵀ on vectors, unrolled along the tree, beat factoring each lane with the scalar
solve (panda arm 230 against 384 ns a state).

A build compiles the widest variant the CPU runs (a variant adds ~60 % to the C compile:
ur5 0.7 -> 1.1 s, panda arm 1.0 -> 1.5 s of compiler CPU), or the one named by the environment variable
``ROBODYN_SIMD`` (``sse2``, ``avx2``, ``avx512``; ``scalar`` for none, ``auto`` the default);
the source, and so the cache key, names the variant. The loaded module checks the CPU
(``__builtin_cpu_supports``) and runs scalar batches where the variant cannot run;
:attr:`robodyn.compiled.CompiledRobot.instruction_set` tells which runs. Only x86-64
builds get vector variants; elsewhere, or when a compiler rejects the vector code (a
function the kernels call that the vector printer passes through, or kernels calling libm's
``sin``/``cos``), batches run the scalar kernels.
"""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path
from types import ModuleType

from robodyn.exceptions import InputError

#: The environment variable that forces an instruction set.
ENVIRONMENT = "ROBODYN_SIMD"
#: (name, lanes, GCC target): the x86-64 variants, narrowest first.
VARIANTS = (("sse2", 2, "sse2"), ("avx2", 4, "avx2"), ("avx512", 8, "avx512f"))
_TEMPLATE = Path(__file__).with_name("simd.c")
_KERNELS = ("gravity", "nle", "mass", "mass_nle", "tau")
_HEADER = re.compile(r"^static void rd_(\w+)\((.*)\) \{$")
_COMMON = """
/* ---- SIMD blocks (robodyn.compiled.simd) ---- */
#if defined(__x86_64__) && defined(__GNUC__)
#define RD_SIMD 1
#pragma STDC FP_CONTRACT OFF
typedef int (*rds_block)(const double *const *in, double *out);
typedef struct {{
    const char *name;
    int lanes;
    rds_block tau, mass, nle, gravity, fd;
}} rds_blocks;
"""
_DISPATCH = """
#define RDS_COUNT {count}
static const char *const rds_names[RDS_COUNT] = {{"scalar", {names}}};
static const rds_blocks *const rds_variants[RDS_COUNT] = {{NULL, {tables}}};
static int rds_supported(int level) {{
    __builtin_cpu_init();
    switch (level) {{
{cases}
    default: return 1;
    }}
}}
static int rds_level = -1; /* -1: not chosen yet (the widest the CPU runs) */
static const rds_blocks *rds_current(void) {{
    if (rds_level < 0)
        for (rds_level = RDS_COUNT - 1; rds_level > 0 && !rds_supported(rds_level); --rds_level) {{}}
    return rds_variants[rds_level];
}}
#endif
"""


def _functions(kernels: str) -> dict[str, list[str]] | None:
    """The kernels' functions by name (``tau`` -> its lines, header to closing brace), or
    None when one of the five is missing."""
    found: dict[str, list[str]] = {}
    current: list[str] | None = None
    for line in kernels.splitlines():
        match = _HEADER.match(line)
        if match and match.group(1) in _KERNELS:
            current = found.setdefault(match.group(1), [line])
        elif current is not None:
            current.append(line)
            if line == "}":
                current = None
    return found if set(found) == set(_KERNELS) else None


def _lanes(lanes: int, value: str) -> str:
    """C filling ``r`` lane by lane with ``value`` (of lane ``l``) and returning it."""
    return f"for (int l = 0; l < {lanes}; ++l) r[l] = {value}; return r;"


def vector_trig(vector: str, lanes: int, attribute: str) -> list[str]:
    """``{vector}_sin``, ``_cos``, ``_sincos``: the kernels' own ``RD_TRIG_DEFINE`` (``trig.c``,
    defined in the kernels' text) on vectors, with its helpers (bit casts; libm's sin and cos
    on the lanes beyond its range, as the scalar ``rd_sin`` does).

    Args:
        vector: The C name of the vector type of doubles (e.g. ``rds4``), the functions' prefix.
        lanes: The doubles in one vector (2, 4 or 8).
        attribute: The functions' C attribute (the instruction set's ``target``).
    """
    inline = f"static inline __attribute__((always_inline)) {attribute}"
    return [
        f"typedef unsigned long long {vector}u __attribute__((vector_size({8 * lanes})));",
        f"#define {vector}_bits(x) (({vector}u)(x))",
        f"#define {vector}_double(u) (({vector})(u))",
        f"#define {vector}_mask(c) (({vector}u)(c))",
        f"{inline} void {vector}_libm({vector} x, {vector}u m, {vector} *s, {vector} *c) {{"
        f" for (int l = 0; l < {lanes}; ++l) if (m[l]) {{ (*s)[l] = sin(x[l]); (*c)[l] = cos(x[l]); }} }}",
        f"RD_TRIG_DEFINE({vector}_, {vector}, {vector}u, {attribute})",
    ]


def _variant(functions: dict[str, list[str]], name: str, lanes: int, target: str) -> list[str] | None:
    """One instruction set's vector kernels and blocks, or None if a kernel has a statement
    the vector printer does not take."""
    from robodyn.equations.c_printer import vector_lines  # sympy: only when a module is built

    vector = f"rds{lanes}"
    attribute = f'__attribute__((target("{target}")))'
    out = [f"typedef double {vector} __attribute__((vector_size({8 * lanes})));"]
    inline = f"static inline __attribute__((always_inline)) {attribute}"
    for function in ("sqrt", "fabs"):
        out.append(f"{inline} {vector} {vector}_{function}({vector} x) {{ {vector} r; {_lanes(lanes, f'{function}(x[l])')} }}")
    out.append(f"{inline} {vector} {vector}_pow({vector} x, double n) {{ {vector} r; {_lanes(lanes, 'pow(x[l], n)')} }}")
    # Lanes gathered into a vector by an initialiser (in registers; writing lanes to memory one by
    # one and reading the vector back stalls store forwarding).
    gather = ", ".join(f"(p)[{lane} * (n)]" for lane in range(lanes))
    out.append(f"#define {vector}_gather(p, n) (({vector}){{{gather}}})")
    out += vector_trig(vector, lanes, attribute)
    out.append(f"{inline} {vector} {vector}_splat(double x) {{ {vector} r; {_lanes(lanes, 'x')} }}")
    for kernel in _KERNELS:
        lines = functions[kernel]
        header = _HEADER.match(lines[0])
        assert header is not None  # _functions matched it
        arguments = header.group(2).replace("double", vector)
        body = vector_lines(lines[1:-1], vector=vector, prefix=f"{vector}_", kernels=[f"rd_{k}" for k in _KERNELS])
        if body is None:
            return None
        out += [f"static {attribute} void {vector}_{kernel}({arguments}) {{", *body, "}"]
    template = _TEMPLATE.read_text(encoding="utf-8")
    out.append(f"enum {{ {vector}_lanes = {lanes} }};")
    # The runtime's tree LDLᵀ (core.c's RD_LDL_DEFINE) on vectors: 1 if a lane's pivot is bad.
    out.append(
        f"{inline} int {vector}_pivot_bad({vector} d) {{ int bad = 0; for (int l = 0; l < {lanes}; ++l) bad |= !(d[l] > 0.0) || !isfinite(d[l]); return bad; }}"
    )
    out.append(f"RD_LDL_DEFINE({inline}, {vector}_, {vector})")
    scatter = " ".join(f"rows[{lane} * n + j] = x[{lane}];" for lane in range(lanes))
    template = (
        template.replace("RDS_SCATTER", scatter)
        .replace("RDS_VZEROUPPER", "__builtin_ia32_vzeroupper();" if lanes > 2 else "")
        .replace("RDS_TARGET", attribute)
        .replace("RDS_NAME", f'"{name}"')
        .replace("RDS_L", str(lanes))
    )
    return [*out, template.replace("rdsT", vector)]


def _wanted() -> str:
    """``$ROBODYN_SIMD``, lower case (empty when unset).

    Raises:
        InputError: If it names no instruction set.
    """
    wanted = os.environ.get(ENVIRONMENT, "").strip().lower()
    names = ("auto", "scalar", *(name for name, _, _ in VARIANTS))
    if wanted and wanted not in names:
        raise InputError(ENVIRONMENT, f"one of {', '.join(names)}", repr(wanted))
    return wanted


@functools.lru_cache(maxsize=1)
def _cpu_flags() -> frozenset[str] | None:
    """The CPU's feature flags (Linux ``/proc/cpuinfo``, read once a process), or None where
    they cannot be read."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            for line in info:
                if line.startswith("flags"):
                    return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return None


def build_variants() -> tuple[tuple[str, int, str], ...]:
    """The variants a build compiles: the one ``$ROBODYN_SIMD`` names (none for ``scalar``),
    else the widest this CPU runs, or every one where the CPU's flags cannot be read (each
    variant costs as much compile time as the scalar kernels; the module checks the CPU when
    it runs and falls back to scalar batches).

    Raises:
        InputError: If ``$ROBODYN_SIMD`` names no instruction set.
    """
    wanted = _wanted()
    named = tuple(variant for variant in VARIANTS if variant[0] == wanted)
    if wanted == "scalar" or named:
        return named
    flags = _cpu_flags()
    return VARIANTS if flags is None else tuple(variant for variant in VARIANTS if variant[2] in flags)[-1:]


def vector_source(kernels: str, variants: tuple[tuple[str, int, str], ...] | None = None) -> str:
    """The SIMD variants of a robot's kernels (C, placed after the kernels and before
    ``runtime.c``, which then defines ``RD_SIMD`` batches); empty when there are none to
    build, the kernels are not the five of :mod:`robodyn.compiled.codegen` or use a function
    the vector printer does not take (the batches then run the scalar kernels).

    Args:
        kernels: The robot's kernels.
        variants: Which of :data:`VARIANTS`; default :func:`build_variants`.
    """
    variants = build_variants() if variants is None else variants
    functions = _functions(kernels)
    sizes = re.findall(r"^#define RD_N[QV] (\d+)$", kernels, flags=re.MULTILINE)
    if (
        functions is None
        or "static const int rd_ancestor[RD_NV][RD_NV]" not in kernels
        or not variants
        or len(set(sizes)) != 1
        or "RD_TRIG_DEFINE(" not in kernels
    ):
        return ""  # the blocks read q with the stride of v: not for a configuration of another size
    out = [_COMMON.format()]
    for name, lanes, target in variants:
        variant = _variant(functions, name, lanes, target)
        if variant is None:
            return ""
        out += variant
    cases = "\n".join(
        f'    case {k + 1}: return __builtin_cpu_supports("{target}");' for k, (_, _, target) in enumerate(variants)
    )
    out.append(
        _DISPATCH.format(
            count=len(variants) + 1,
            names=", ".join(f'"{name}"' for name, _, _ in variants),
            tables=", ".join(f"&rds{lanes}_blocks" for _, lanes, _ in variants),
            cases=cases,
        )
    )
    return "\n".join(out) + "\n"


def instruction_sets(module: ModuleType) -> tuple[str, ...]:
    """The instruction sets a loaded module can run on this CPU (``"scalar"`` first).

    Args:
        module: A loaded robot module (:func:`robodyn.compiled.build.robot_module`).
    """
    return tuple(module.info().get("instruction_sets", ("scalar",)))


def configure(module: ModuleType) -> ModuleType:
    """Apply ``$ROBODYN_SIMD`` (if set) to a freshly loaded robot module; returns the module.

    Args:
        module: The freshly loaded robot module.

    Raises:
        InputError: If the variable names no instruction set this module runs on this CPU.
    """
    wanted = _wanted()
    if not wanted:
        return module
    available = instruction_sets(module)
    if wanted in ("auto", *available):
        if hasattr(module, "simd"):
            module.simd(available[-1] if wanted == "auto" else wanted)
    else:
        raise InputError(ENVIRONMENT, f"one of auto, {', '.join(available)} (what this CPU and build run)", repr(wanted))
    return module
