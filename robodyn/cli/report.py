"""``robodyn info``: a robot's description as the command line prints it (text or JSON).

Every number printed carries its unit (from ``robot.dofs``) or says what it is. The
dynamics terms of ``robodyn equations`` are :mod:`robodyn.dynamics.terms`; a simulation's
summary is :mod:`robodyn.sim.report`.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.text import counted, printable
from robodyn.dynamics import frames
from robodyn.dynamics.robot import Robot


def end_effector_text(robot: Robot) -> tuple[str | None, str]:
    """The default end effector, or ``None`` and why there is none.

    Args:
        robot: The loaded robot.
    """
    from robodyn.exceptions import AmbiguousEndEffectorError

    try:
        return robot.end_effector, ""
    except AmbiguousEndEffectorError as error:
        tips = ", ".join(printable(tip) for tip in error.candidates)
        return None, f"none: {len(error.candidates)} chain tips ({tips}); pass --frame"


def info_dict(robot: Robot) -> dict:
    """A JSON-ready description of a robot: joints, limits, masses, default end effector
    (``null`` with ``end_effector_candidates`` when it has several chains).

    Args:
        robot: The loaded robot.
    """

    def finite(value: float) -> float | None:
        return float(value) if np.isfinite(value) else None

    lower, upper = robot.physical_limits()
    offset = 1 if robot.floating_base else 0
    limited = [False] * offset + [bool(np.isfinite(lo) or np.isfinite(up)) for lo, up in zip(lower, upper, strict=True)]
    return {
        "name": robot.name,
        "robot_name": robot.spec.name,
        "file_format": robot.source.file_format,
        "source": robot.source.label if len(robot.source.label) < 300 else "<text>",
        "nq": robot.nq,
        "nv": robot.nv,
        "floating_base": robot.floating_base,
        "gravity_m_s2": robot.gravity_vector.tolist(),
        "end_effector": end_effector_text(robot)[0],
        "end_effector_candidates": frames.end_effector_candidates(robot.model),
        "joints": [
            {
                "name": j.name,
                "type": j.type,
                "lower": finite(j.lower),
                "upper": finite(j.upper),
                "effort": finite(j.effort),
                "velocity": finite(j.velocity),
                "position_limited": limited[index],
            }
            for index, j in enumerate(robot.joints)
        ],
        "link_masses_kg": robot.link_masses,
        "total_mass_kg": robot.total_mass,
        "mimic_joints": mimic_joints(robot),
        "joint_dynamics": [
            {"joint": dof.joint, "damping": dof.damping, "friction": dof.friction, "armature": dof.armature}
            for dof in robot.dofs
            if not dof.is_base
        ],
        "package_paths": package_paths(robot),
        "constraints": [
            {"kind": constraint.kind, "name": constraint.name, "rows": constraint.rows, "description": str(constraint)}
            for constraint in robot.constraints
        ],
        "constraint_rank_at_neutral": robot.constraint_rank(robot.neutral_configuration()) if robot.constraints else 0,
    }


def mimic_joints(robot: Robot) -> list[dict]:
    """The robot's mimic joints: ``q = multiplier * q_source + offset``, in document order.

    Args:
        robot: The loaded robot.
    """
    return [
        {"joint": joint.name, "source": joint.mimic.joint, "multiplier": joint.mimic.multiplier, "offset": joint.mimic.offset}
        for joint in robot.spec.joints.values()
        if joint.mimic is not None
    ]


def package_paths(robot: Robot) -> dict[str, list[str]]:
    """Where the robot's ``package://`` paths resolve: ``packages=``, ``$ROS_PACKAGE_PATH``, the zoo.

    Args:
        robot: The loaded robot.
    """
    from robodyn.urdf.packages import PackageLookup

    dirs = robot.source.package_dirs
    if isinstance(dirs, PackageLookup):
        return dirs.as_dict()
    return {"packages": [], "ros_package_path": [], "zoo": [str(folder) for folder in dirs]}


def info_text(robot: Robot) -> str:
    """A readable description of a robot: joints with types and limits, link masses.

    Args:
        robot: The loaded robot.
    """
    end_effector, reason = end_effector_text(robot)
    also = f' ("{printable(robot.name)}")' if robot.name != robot.spec.name else ""
    kind = {"xacro": ", expanded from xacro", "mjcf": ", read from MJCF"}.get(robot.source.file_format, "")
    lines = [
        f"robot {printable(robot.spec.name)}{also}{kind}: {counted(robot.nv, 'degree')} of freedom (nq = {robot.nq}), "
        f"{'floating' if robot.floating_base else 'fixed'} base, gravity {_vector(robot.gravity_vector, 4)} m/s²",
        f"end effector (default task frame): {printable(end_effector) if end_effector else reason}",
        "",
        f"{'joint':30s} {'type':11s} {'lower':>10s} {'upper':>10s} {'effort':>10s} {'velocity':>10s}",
    ]
    if robot.floating_base:
        lines.append(f"{printable(robot.joints[0].name):30s} {'floating':11s} {'(base pose: x y z, quaternion x y z w)':>43s}")
    lower, upper = robot.physical_limits()
    open_limits = 0
    for index, dof in enumerate(dof for dof in robot.dofs if not dof.is_base):
        marks = [
            "*" if np.isfinite(given) and not np.isfinite(used) else ""
            for given, used in ((dof.lower, lower[index]), (dof.upper, upper[index]))
        ]
        marks += ["*" if given == 0 else "" for given in (dof.effort_limit, dof.velocity_limit)]
        open_limits += sum(bool(mark) for mark in marks)
        lines.append(
            f"{printable(dof.joint):30s} {dof.joint_type:11s} {_limit(dof.lower, dof.position_unit) + marks[0]:>10s} "
            f"{_limit(dof.upper, dof.position_unit) + marks[1]:>10s} {_limit(dof.effort_limit, dof.effort_unit) + marks[2]:>10s} "
            f"{_limit(dof.velocity_limit, dof.velocity_unit) + marks[3]:>10s}"
        )
    if open_limits:
        lines.append("* a placeholder (|limit| ≥ 1e3, lower = upper, or 0 effort / velocity): treated as no limit")
    lines += _dynamics_lines(robot) + _mimic_lines(robot) + _constraint_lines(robot) + _package_lines(robot)
    lines += ["", f"{'link':30s} {'mass':>12s}"]
    lines += [f"{printable(name):30s} {mass:>9.4g} kg" for name, mass in robot.link_masses.items()]
    lines.append(f"{'total':30s} {robot.total_mass:>9.4g} kg")
    return "\n".join(lines)


def _constraint_lines(robot: Robot) -> list[str]:
    """The robot's constraints (its file's ``<equality>`` and ``load(constraints=)``'s), one a line."""
    constraints = robot.constraints
    if not constraints:
        return []
    rows = sum(constraint.rows for constraint in constraints)
    rank = robot.constraint_rank(robot.neutral_configuration())
    redundant = f"; {rows - rank} redundant at the neutral configuration (λ least-norm)" if rank < rows else ""
    return ["", f"constraints ({rows} rows{redundant}; docs/constraints.md):"] + [f"  {printable(str(c))}" for c in constraints]


def _dynamics_lines(robot: Robot) -> list[str]:
    """Damping, friction and armature of each joint, when any joint has one."""
    dofs = [dof for dof in robot.dofs if not dof.is_base]
    if not any(dof.damping or dof.friction or dof.armature for dof in dofs):
        return ["", "joint damping, friction, armature: none"]
    lines = ["", f"{'joint':30s} {'damping b':>16s} {'friction f':>12s} {'armature':>14s}"]
    for dof in dofs:
        inertia = "kg m²" if dof.kind == "angular" else "kg"
        damping = f"{dof.damping:.4g} {dof.effort_unit} s/{dof.position_unit}"
        lines.append(
            f"{printable(dof.joint):30s} {damping:>16s} {f'{dof.friction:.4g} {dof.effort_unit}':>12s} "
            f"{f'{dof.armature:.4g} {inertia}':>14s}"
        )
    return lines


def _mimic_lines(robot: Robot) -> list[str]:
    mimics = mimic_joints(robot)
    if not mimics:
        return []
    lines = ["", "mimic joints (q = multiplier × q_source + offset):"]
    for mimic in mimics:
        lines.append(
            f"  {printable(mimic['joint'])} = {mimic['multiplier']:.6g} × {printable(mimic['source'])} + {mimic['offset']:.6g}"
        )
    return lines


def _package_lines(robot: Robot) -> list[str]:
    paths = package_paths(robot)
    shown = [f"{item} (--package)" for item in paths["packages"]]
    shown += [f"{item} ($ROS_PACKAGE_PATH)" for item in paths["ros_package_path"]]
    shown += [f"{item} (zoo)" for item in paths["zoo"]]
    return ["", "package paths: " + ("; ".join(printable(item) for item in shown) if shown else "none")]


def _limit(value: float, unit: str) -> str:
    return "-" if not np.isfinite(value) else f"{value:.4g} {unit}"


def _vector(values: np.ndarray, precision: int) -> str:
    return "[" + ", ".join(f"{value:.{precision}g}" for value in values) + "]"
