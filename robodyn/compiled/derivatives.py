"""Derivatives of the compiled dynamics: ``∂τ/∂q``, ``∂τ/∂v`` and ``∂q̈/∂q``, ``∂q̈/∂v`` in C.

``∂τ/∂q`` and ``∂τ/∂v`` are the Newton–Euler program (the one the ``tau`` kernel runs)
differentiated in reverse, assignment by assignment (:mod:`robodyn.compiled.tangents`): for
``x = e(y1, y2, …)`` the partials ``∂e/∂y`` are printed once, and the reverse sweep's
``ȳ ← ȳ + ∂e/∂y · x̄`` is one SIMD statement over the outputs (``τ_0 … τ_{n−1}`` in the
lanes of one vector), one sweep for both ``∂τ/∂q`` and ``∂τ/∂v``, seeded through the
bodies' linear map (``θ = S q + offset``, ``θ̇ = S v``: mimic joints included).
``∂τ/∂a = M`` is the ``mass`` kernel.

The forward dynamics' derivatives follow: ``q̈ = FD(q, v, τ)`` (the LDLᵀ of ``M``),
``∂q̈/∂x = −M⁻¹ ∂τ/∂x`` at ``a = q̈`` and ``∂q̈/∂τ = M⁻¹``, the three solved with the one
factorisation (``derivatives.c``'s ``rdd_columns``: one reciprocal of a pivot a row, times
each entry, in the single call, the pairs and the blocks alike).
The kernels make a module of their own, built on the first derivative asked for
(:func:`derivative_module`) and cached like the robot's (:mod:`robodyn.compiled.build`;
about as much CPU as the robot's ``tau`` program, plus the C compiler). The functions::

    static void rdd_tau_derivatives(const double *q, const double *v, const double *a,
                                    double *dq, double *dv);   /* (nv, nv) row-major each */
    static void rdd_tau_derivatives2(...);  /* 2 states, SSE2; rdd8_...: 8 states, AVX-512 */

The single call runs the outputs in lanes (the widest instruction set of the build the CPU
runs: panda arm ∂τ 0.39× Pinocchio's ``computeRNEADerivatives``, against 0.43× in forward
mode with its directions in lanes and 0.78× written direction by direction); its scalar
part, ``M`` (``rd_mass``) or the forward dynamics' ``rd_mass_nle``, ``q̈`` and LDLᵀ of ``M``,
is compiled for that instruction set too (tangent_single.py's ``_SCALAR``: the same IEEE
operations, so the same bits, in three-operand forms and, with AVX-512, 32 registers: ~9 %
of a panda-arm ∂q̈ call at -O1). A batch runs states in lanes instead: ``L`` rows at a time through the variant
of the instruction set the build chose (:func:`robodyn.compiled.simd.build_variants`, as the
dynamics' SIMD blocks: the widest the CPU runs, or ``$ROBODYN_SIMD``; 2, 4 or 8 lanes,
compiled with that ``target`` attribute and chosen at run time with
``__builtin_cpu_supports``), else two at a time (``rdd_tau_derivatives2``, plain SSE2), on
the runtime's thread pool, the same statements written lane by lane: the same IEEE
operations in the same order as the single call's lane (no FMA: contraction is off), so
each row equals its single call; ``cos``/``sin`` are the kernels' own (``trig.c``:
``rd_sincos`` in the single call, its vector form in the blocks, as the dynamics' SIMD
blocks). A block hands ``∂τ`` on as vectors (the forward dynamics' solves take them as they
are) and writes each state's rows in order at the end; a batch's three results are views of
one buffer (one allocation, which the allocator keeps for the next call: three were handed
back to the system and their pages faulted in again each call).

Why the program differentiated, not the analytical recursions (Carpentier and Mansard
2018): the program is exact for every robot the compiled engine takes (mimic joints, oblique
axes, prismatic joints), constants folded, structural zeros known; the recursions in world
coordinates (Pinocchio's ``computeRNEADerivatives``) cost about as many operations on a
7-joint arm (~9 000 by an estimate of its 6×6 products; a panda-arm block of 8 states is
9 400 AVX-512 instructions), and the sweep's statements over outputs are SIMD statements.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import cast

import numpy as np

from robodyn.compiled import build, simd
from robodyn.compiled.cache import robot_key
from robodyn.compiled.programs import dynamics_programs, robot_bodies
from robodyn.compiled.tangents import TangentWriter
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import CompileError, NonFiniteResultError, SingularMassMatrixError

_RUNTIME = Path(__file__).with_name("derivatives.c")


def derivative_module(robot: Robot, *, kernels: Callable[[], str]) -> ModuleType:
    """The robot's derivative module: found by the robot's key, else generated, built and cached.

    The Newton–Euler program differentiated is the robot's cached one
    (:func:`robodyn.compiled.programs.dynamics_programs`, the one its ``tau`` kernel prints).

    Args:
        robot: A fixed-base robot the compiled engine took.
        kernels: Gives its kernels' C source (the module calls ``rd_mass``, ``rd_mass_nle``);
            asked for only for a build.

    Raises:
        CompileError: If the build fails or the module does not match the robot.
    """
    variants = simd.build_variants()
    own = "derivatives-" + robot_key(robot) + "-simd=" + " ".join(name for name, _, _ in variants)

    def source() -> str:
        derivative = build.cached_kernels(own)
        if derivative is None:
            bodies = robot_bodies(robot)
            derivative = TangentWriter(dynamics_programs(robot).tau, bodies.selection, bodies.offset, variants).source()
            build.store_kernels(own, derivative)
        runtime = build.runtime_source() + "\n" + _RUNTIME.read_text(encoding="utf-8")
        robot_kernels = kernels()  # and their SIMD variants: the forward dynamics' part of a block
        vectors = simd.vector_source(robot_kernels, variants)
        return paired_trig(robot_kernels) + "\n" + vectors + derivative + "\n" + runtime

    module = build.keyed_extension(own, source, init="rdd_module", label=robot.name)
    if module.info()["nv"] != robot.nv:
        raise CompileError(robot.name, "the cached derivative kernels do not match the robot; clear the cache folder")
    return module


def paired_trig(kernels: str) -> str:
    """The kernels' C with each function's ``rd_sin(x)`` and ``rd_cos(x)`` of one ``x`` as one
    ``rd_sincos`` where the first of the two stood (each of the two computes both: the
    compiler does not always merge them); the same results, bit for bit.

    Args:
        kernels: The C source of the robot's kernels, one statement a line.

    Returns:
        The same source with each function's pairs merged.
    """
    pattern = re.compile(r"^    const double (\w+) = rd_(sin|cos)\((\w+)\);$")
    lines = kernels.splitlines()
    first: dict[tuple[str, str], int] = {}
    for index, line in enumerate(lines):
        if not line.startswith(" "):
            first = {}  # a function's start or end, or text between: pairs only within a function
        match = pattern.match(line)
        if match is None:
            continue
        name, function, argument = match.groups()
        other = first.get(("cos" if function == "sin" else "sin", argument))
        if other is None:
            first[(function, argument)] = index
            continue
        partner = pattern.match(lines[other])
        assert partner is not None
        sine, cosine = (name, partner.group(1)) if function == "sin" else (partner.group(1), name)
        lines[other] = f"    double {sine}, {cosine}; rd_sincos({argument}, &{sine}, &{cosine});"
        lines[index] = ""
        del first[("cos" if function == "sin" else "sin", argument)]
    return "\n".join(lines) + "\n"


def checked(function, robot: Robot, threads: int, kind: str, **named: object) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The checked path of a derivative call: validate, convert, compute again, refuse what
    is not finite (the errors of :class:`robodyn.compiled.CompiledRobot`'s methods).

    Args:
        function: The module's ``tau_derivatives`` or ``fd_derivatives``.
        robot: The robot (its input checks).
        threads: Native threads for a batch.
        kind: ``"tau"`` or ``"fd"``.
        named: The state arguments by name (``q``, ``v``, and ``a`` or ``tau``).
    """
    arrays, _ = robot.validate(**named)
    arrays = [np.ascontiguousarray(array, dtype=np.float64) for array in arrays]
    result = function(*arrays, threads)
    if result.__class__ is tuple:
        return cast(tuple[np.ndarray, np.ndarray, np.ndarray], result)
    if result == 3 or kind == "fd":
        raise SingularMassMatrixError(robot.name, robot.massless_joints)
    if result is None or result == 1:  # cannot happen after validate(): refuse rather than guess
        raise CompileError(robot.name, f"the compiled {kind} derivatives refused checked inputs (status {result})")
    raise NonFiniteResultError(robot.name, "the derivatives of tau")
