"""The robots the export tests share, their modules (derived once a process), and the comparison."""

from __future__ import annotations

import numpy as np

import robodyn
from robodyn.export.programs import ExportPrograms, export_programs
from robodyn.export.source import Backend, module_text
from tests.conftest import NONDEGENERATE_CASES

#: Test robots (mimic with multipliers and offsets, oblique axes, prismatic joints, locked
#: joints) and one with gravity off the z axis.
CASES = {
    name: NONDEGENERATE_CASES[name]
    for name in ("oblique", "oblique_locked", "gripper", "gripper_locked_prismatic", "mimic_tree", "mimic_tree_locked")
}
CASES["gripper_tilted_gravity"] = (
    NONDEGENERATE_CASES["gripper_locked_prismatic"][0],
    {**NONDEGENERATE_CASES["gripper_locked_prismatic"][1], "gravity": (1.3, -2.1, -9.3)},
)
#: The fast tier's share (the derivation of an oblique or branching robot takes seconds).
FAST_CASES = ("oblique_locked", "gripper_locked_prismatic", "gripper_tilted_gravity")

_PROGRAMS: dict[str, tuple[robodyn.Robot, ExportPrograms]] = {}


def exported(case: str, backend: Backend = "casadi") -> tuple[robodyn.Robot, str]:
    """The robot of a case (a name of :data:`CASES` or a zoo robot) and its module (the
    programs derived once per test process)."""
    if case not in _PROGRAMS:
        path, options = CASES.get(case, (case, {}))
        robot = robodyn.load(path, **options)
        _PROGRAMS[case] = (robot, export_programs(robot))
    robot, programs = _PROGRAMS[case]
    return robot, module_text(programs, backend)


def column(x) -> np.ndarray:
    return np.array(x, dtype=float).ravel()


def differences(robot: robodyn.Robot, functions: dict, q, v, a) -> dict[str, float]:
    """Largest relative difference of every exported function from the engine at one state."""

    def relative(ours, theirs) -> float:
        ours, theirs = np.asarray(ours, float).reshape(np.shape(theirs)), np.asarray(theirs)
        return float(np.max(np.abs(ours - theirs)) / max(1.0, float(np.max(np.abs(theirs)))))

    result = {
        "inverse_dynamics": relative(functions["inverse_dynamics"](q, v, a), robot.inverse_dynamics(q, v, a)),
        "mass_matrix": relative(functions["mass_matrix"](q), robot.mass_matrix(q)),
        "nonlinear_effects": relative(functions["nonlinear_effects"](q, v), robot.nonlinear_effects(q, v)),
        "gravity": relative(functions["gravity"](q), robot.gravity(q)),
        "forward_dynamics": relative(functions["forward_dynamics"](q, v, a), robot.forward_dynamics(q, v, a)),
    }
    for frame in robot.frame_names:
        result["frame_position:" + frame] = relative(functions["frame_position:" + frame](q), robot.frame_position(q, frame))
        result["frame_jacobian:" + frame] = relative(functions["frame_jacobian:" + frame](q), robot.frame_jacobian(q, frame))
    return result
