"""A coordinate whose cosine alone enters ``τ`` (a pendulum swinging in the plane of gravity):
the derivative kernels print it with the kernels' own ``rd_cos``, which the batches have in
SIMD form, so the batches still run states in lanes, and its derivatives obey the pendulum's
law. Found by mutation testing (issue 39): libm's ``cos`` there passed every other test, the
batches silently falling back to one state at a time (the mimic tree uses every
coordinate's sine and cosine together). Writing these tests found that such a robot's
derivative module did not compile at all (the derivative of the lone ``cos θ`` read a
``sin θ`` never printed): the generator now prints each sine's and cosine's partner."""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.compiled import compile
from robodyn.compiled.programs import dynamics_programs, robot_bodies
from robodyn.compiled.tangents import TangentWriter
from robodyn.equations.program import needed
from tests.compiled_helpers import shared_cache

#: Mars' gravity, along z: the swing axis y is horizontal, so ``τ = I θ̈ + m g_z l cos θ`` (no sine).
GRAVITY = (0.0, 0.0, -3.71)
MASS, LENGTH, IYY = 1.5, 0.4, 0.02
PENDULUM = f"""<robot name="pendulum"><link name="base"/>
<joint name="swing" type="revolute"><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/>
<limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
<link name="bob"><inertial><origin xyz="{LENGTH} 0 0"/><mass value="{MASS}"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="{IYY}" iyz="0" izz="0.015"/></inertial></link></robot>"""
#: The kernels' own sine and cosine (trig.c) and their vector forms (``rd_cos``, ``rd_sincos``,
#: ``rdd_cos_2``, ``rdd8_sin``, ``rds8_sincos``): libm's ``sin``, ``cos`` have no vector form here.
OWN_TRIG = re.compile(r"(?:rd|rdd|rdd\d+|rds\d+)_(?:sin|cos|sincos)(?:_2)?")
TRIG = (sp.sin, sp.cos)
#: One build variant, named: the generated text does not depend on the CPU running the test.
VARIANTS = [("avx512", 8, "avx512f")]


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's: the derived programs are kept there too)."""
    with shared_cache() as folder:
        yield folder


def _writer(robot) -> TangentWriter:
    bodies = robot_bodies(robot)
    return TangentWriter(dynamics_programs(robot).tau, bodies.selection, bodies.offset, VARIANTS)


def _trig_calls(source: str) -> set[str]:
    """The sine and cosine functions the source calls (a name ending in ``sin``, ``cos`` or
    ``sincos``, with an optional ``_2``: not ``rdd_single_mass``)."""
    return set(re.findall(r"\b((?:\w+_)?(?:sin|cos|sincos)(?:_2)?)\(", source))


def _batch_forms(source: str) -> tuple[bool, bool]:
    """Whether the derivative source defines the pairs (two states, SSE2) and the blocks (L states)."""
    return "#define RDD_PAIRS 1" in source, "#define RDD_BLOCKS(X) X(rdd8, 8," in source


def test_a_coordinate_whose_cosine_alone_enters_tau_keeps_the_batches_in_simd_lanes():
    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    tau = dynamics_programs(robot).tau
    trig = {type(expr).__name__ for _, expr in needed(tau.assignments, list(tau.outputs["tau"])) if isinstance(expr, TRIG)}
    assert trig == {"cos"}  # the robot is the case: τ reads cos θ alone
    source = _writer(robot).source()
    calls = _trig_calls(source)
    assert "rd_cos" in calls and all(OWN_TRIG.fullmatch(name) for name in calls), calls
    assert _batch_forms(source) == (True, True)
    # Negative control: the same text calling libm's sin and cos is refused.
    calls = _trig_calls(re.sub(r"\brd_(sin|cos)\(", r"\1(", source))
    assert not all(OWN_TRIG.fullmatch(name) for name in calls), calls


def _states(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q = rng.uniform(-3.0, 3.0, size=(count, 1))
    return q, rng.normal(size=(count, 1)), rng.normal(size=(count, 1))


@pytest.mark.slow
def test_the_pendulums_compiled_derivatives_obey_its_law_in_lanes_and_row_by_row(rng):
    """``∂τ/∂θ = −m g_z l sin θ``, ``∂τ/∂θ̇ = 0``, ``∂τ/∂θ̈ = I_yy + m l²``, for a batch of
    ``2L + 1`` states (not a multiple of the lanes) run in SIMD blocks, each row its single
    call; negative control: the law with the other sign of gravity fails."""
    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    compiled = compile(robot, threads=2)
    info = compiled._derivatives().info()
    q, v, a = _states(rng, 2 * info["lanes"] + 1)
    dq, dv, mass = compiled.inverse_dynamics_derivatives(q, v, a)
    rows = [compiled.inverse_dynamics_derivatives(q[i], v[i], a[i]) for i in range(len(q))]
    assert info["instruction_set"] != "scalar" and info["lanes"] >= 2, info
    law = -MASS * GRAVITY[2] * LENGTH * np.sin(q[:, 0])
    assert np.allclose(dq[:, 0, 0], law, rtol=1e-12, atol=1e-12)
    assert not np.allclose(dq[:, 0, 0], -law, rtol=1e-6, atol=1e-6)
    assert np.array_equal(dv, np.zeros_like(dv))
    assert np.allclose(mass[:, 0, 0], IYY + MASS * LENGTH**2, rtol=1e-12)
    for i, single in enumerate(rows):
        assert all(np.array_equal(batch[i], one) for batch, one in zip((dq, dv, mass), single, strict=True)), i
