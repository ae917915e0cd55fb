"""Fuzzing the loader: mutated URDFs either load as a valid model or raise a robodyn error.

Never another exception, never a silent non-finite model. The slow tier runs many more
cases in a child process, so that a crash in native code would be reported, not fatal.
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn
from robodyn.common.text import is_printable
from tests.conftest import ROOT

SEEDS = [
    robodyn.rp_arm_urdf(),
    (ROOT / "tests" / "data" / "two_branches.urdf").read_text(),
    (ROOT / "tests" / "data" / "gantry.urdf").read_text(),
    robodyn.urdf.models.pendulum_urdf(3),
]
TOKENS = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e-308", "", "abc", "1 2", "1 2 3 4", "0 0 0", "  ", "1e-30", "3"]
# hostile spellings and names (issue #14): other parsers read these differently
TOKENS += [" 1.0 ", "1_000", "\uff12", "0x10", "1,5", "+.5", "\u00a01", "x\n robodyn: ok", "\x9b31m", "\u202eevil", "link1"]


def mutate(text: str, operations: list[tuple[int, int, int]]) -> str:
    """Apply mutations, each (kind, where, what) of small integers, to a URDF document."""
    for kind, where, what in operations:
        if kind == 0:  # truncate
            text = text[: where % max(len(text), 1)]
            continue
        try:
            root = ET.fromstring(text)
        except ET.ParseError:
            continue
        nodes = list(root.iter())
        node = nodes[where % len(nodes)]
        if kind == 1 and node.attrib:  # replace an attribute's value
            key = sorted(node.attrib)[what % len(node.attrib)]
            node.set(key, TOKENS[what % len(TOKENS)])
        elif kind == 2 and node is not root:  # delete an element
            for parent in root.iter():
                if node in list(parent):
                    parent.remove(node)
                    break
        elif kind == 3:  # duplicate an element under the root
            root.append(ET.fromstring(ET.tostring(node)))
        elif kind == 4 and node.tag == "joint":  # change a joint's type
            node.set("type", ["revolute", "continuous", "prismatic", "fixed", "floating", "planar", "screw"][what % 7])
        elif kind == 5 and node.attrib:  # rename an attribute
            key = sorted(node.attrib)[what % len(node.attrib)]
            node.set(key + "x", node.attrib.pop(key))
        text = ET.tostring(root, encoding="unicode")
    return text


def check_one(text: str) -> str:
    """Load a document; return "ok" or "refused", raise on anything else."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", robodyn.exceptions.RobodynWarning)
            robot = robodyn.load(text)
    except robodyn.RobodynError as error:
        assert is_printable(str(error)), repr(str(error))  # one printable line, whatever the input
        return "refused"
    q = robot.neutral_configuration()
    zeros = np.zeros(robot.nv)
    mass = robot.mass_matrix(q)
    assert np.isfinite(mass).all() and np.allclose(mass, mass.T)
    assert np.isfinite(robot.inverse_dynamics(q, zeros, zeros)).all()
    with contextlib.suppress(robodyn.SingularMassMatrixError):  # massless moving bodies
        assert np.isfinite(robot.forward_dynamics(q, zeros, zeros)).all()
    return "ok"


operations = st.lists(st.tuples(st.integers(0, 5), st.integers(0, 10_000), st.integers(0, 1000)), min_size=1, max_size=4)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(range(len(SEEDS))), operations)
def test_mutated_urdfs_load_or_are_refused_cleanly(seed, ops):
    check_one(mutate(SEEDS[seed], ops))


FUZZ_PROGRAM = """
import random, sys
sys.path.insert(0, {root!r})
from tests.test_fuzz_urdf import SEEDS, check_one, mutate
rng = random.Random({seed})
outcomes = {{"ok": 0, "refused": 0}}
for case in range({count}):
    ops = [(rng.randrange(6), rng.randrange(10_000), rng.randrange(1000)) for _ in range(rng.randint(1, 5))]
    seed = rng.randrange(len(SEEDS))
    print("case", case, seed, ops, file=sys.stderr, flush=True)
    outcomes[check_one(mutate(SEEDS[seed], ops))] += 1
print(outcomes["ok"], outcomes["refused"])
"""


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_many_mutations_in_a_child_process(seed):
    program = FUZZ_PROGRAM.format(root=str(ROOT), seed=seed, count=1500)
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=600, cwd=ROOT)
    last_case = result.stderr.strip().splitlines()[-1] if result.stderr.strip() else ""
    assert result.returncode == 0, f"child died with {result.returncode} at {last_case}: {result.stderr[-2000:]}"
    ok, refused = map(int, result.stdout.split())
    assert ok + refused == 1500 and ok > 0 and refused > 0
