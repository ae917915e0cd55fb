"""The compiled kernels are the equations layer's programs printed by the one C printer."""

from __future__ import annotations

import dataclasses
import re

import numpy as np

import robodyn
from robodyn.compiled.codegen import KernelWriter
from robodyn.compiled.robot import SNAP, coordinate_parents
from robodyn.equations.compact import derive_compact
from robodyn.equations.newton_euler import derive_newton_euler
from robodyn.equations.program import needed
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.tree import build_tree
from tests.conftest import ROOT


def _writer(name: str) -> tuple[KernelWriter, robodyn.Robot]:
    """The kernel writer of a robot, as :func:`robodyn.compiled.robot.generate_kernels` makes it."""
    robot = robodyn.load(name)
    tree = build_tree(robot.spec, robot.urdf, floating_base=False)
    count = len(tree.bodies)
    free = dataclasses.replace(tree, selection=np.eye(count), offset=np.zeros(count), joint_names=[f"b{i}" for i in range(count)])
    model = ReferenceRobot(free, name=robot.name, urdf=robot.urdf, spec=robot.spec, gravity=robot.gravity_vector)
    column = [tree.joint_names.index(j) for j in robot.joint_names]
    tau = derive_newton_euler(model, snap=SNAP)
    writer = KernelWriter(
        derive_compact(model, snap=SNAP), tree.selection[:, column], tree.offset, coordinate_parents(robot), tau
    )
    return writer, robot


def test_the_tau_kernel_is_the_newton_euler_program_printed():
    writer, robot = _writer(str(ROOT / "tests/data/mimic_arm.urdf"))
    source = writer.source()
    kernel = source[source.index("static void rd_tau") :]
    ne = writer.newton_euler
    assert ne is not None
    statements = re.findall(r"const double r\d+ = ", kernel)
    assert len(statements) == len(needed(ne.assignments, ne.outputs["tau"])) > 0
    # The mimic body's coordinate is made of its leader's, in every array.
    assert re.search(r"const double th\d+ = [-0-9.e]+\*q\[\d\]", source)
    assert robot.nv == len(re.findall(r"    tau\[\d\] = ", kernel))


def test_a_long_program_splits_mass_and_nle_into_calls_with_the_same_numbers(monkeypatch, tmp_path, rng):
    """Above ``SPLIT_ASSIGNMENTS`` the ``M`` and ``C v + G`` kernel calls the two kernels
    (shorter functions for the C compiler): forward dynamics, one state and a batch on the
    SIMD blocks and their remainder rows, bit for bit the one-pass kernel's."""
    from robodyn.compiled import build, codegen

    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    writer, robot = _writer(str(ROOT / "tests/data/mimic_arm.urdf"))
    whole = writer.source()
    monkeypatch.setattr(codegen, "SPLIT_ASSIGNMENTS", 0)
    split = writer.source()
    assert "    rd_mass(q, M);" in split and "    rd_mass(q, M);" not in whole  # negative control: not split by default
    n = robot.nv
    q, v, tau = (np.ascontiguousarray(rng.uniform(-2, 2, (19, n))) for _ in range(3))  # 8k + 3 rows
    one, two = build.build_module(whole, label="whole"), build.build_module(split, label="split")
    for rows in (q[0], v[0], tau[0]), (q, v, tau):
        expected, got = one.fd(*rows, 2), two.fd(*rows, 2)
        assert expected is not None and np.array_equal(expected, got)
