"""Human- and machine-readable reports of a robot: its description and its dynamics terms.

Used by the CLI (``robodyn info``, ``robodyn equations``); every number printed carries its
unit or says what it is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics import frames
from robodyn.dynamics.robot import Robot


@dataclass(frozen=True)
class DynamicsTerms:
    """The terms of ``tau = M(q) a + C(q, v) v + G(q)`` at one state (SI units)."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    M: np.ndarray
    C: np.ndarray
    G: np.ndarray


def equations_at(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> DynamicsTerms:
    """Evaluate ``tau``, ``M``, ``C`` and ``G`` at one state (1-D arrays)."""
    return DynamicsTerms(
        np.asarray(q, float), np.asarray(v, float), np.asarray(a, float),
        robot.inverse_dynamics(q, v, a), robot.mass_matrix(q), robot.coriolis_matrix(q, v), robot.gravity(q),
    )  # fmt: skip


def _dof_types(robot: Robot) -> list[str]:
    """Joint type of each velocity coordinate (a floating base gives 3 linear, 3 angular)."""
    types = []
    for joint in robot.joints:
        types += ["prismatic"] * 3 + ["revolute"] * 3 if joint.type == "floating" else [joint.type]
    return types


def _is_linear(joint_type: str) -> bool:
    return joint_type == "prismatic"


def dof_units(robot: Robot) -> dict[str, list[str]]:
    """Units of each entry of ``q``, ``v``, ``a`` and ``tau``, by velocity coordinate."""
    linear = [_is_linear(t) for t in _dof_types(robot)]
    return {
        "v": ["m/s" if lin else "rad/s" for lin in linear],
        "a": ["m/s^2" if lin else "rad/s^2" for lin in linear],
        "tau": ["N" if lin else "N m" for lin in linear],
    }


def end_effector_text(robot: Robot) -> tuple[str | None, str]:
    """The default end effector, or ``None`` and why there is none."""
    from robodyn.exceptions import AmbiguousEndEffectorError

    try:
        return robot.end_effector, ""
    except AmbiguousEndEffectorError as error:
        tips = ", ".join(printable(tip) for tip in error.candidates)
        return None, f"none: {len(error.candidates)} chain tips ({tips}); pass --frame"


def info_dict(robot: Robot) -> dict:
    """A JSON-ready description of a robot: joints, limits, masses, default end effector
    (``null`` with ``end_effector_candidates`` when it has several chains)."""

    def finite(value: float) -> float | None:
        return float(value) if np.isfinite(value) else None

    lower, upper = robot.physical_limits()
    offset = 1 if robot.floating_base else 0
    limited = [False] * offset + [bool(np.isfinite(lo) or np.isfinite(up)) for lo, up in zip(lower, upper, strict=True)]
    return {
        "name": robot.name,
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
    }


def info_text(robot: Robot) -> str:
    """A readable description of a robot: joints with types and limits, link masses."""
    end_effector, reason = end_effector_text(robot)
    lines = [
        f"robot {printable(robot.name)}: {robot.nv} degrees of freedom (nq = {robot.nq}), "
        f"{'floating' if robot.floating_base else 'fixed'} base, gravity {_vector(robot.gravity_vector, 4)} m/s²",
        f"end effector (default task frame): {printable(end_effector) if end_effector else reason}",
        "",
        f"{'joint':30s} {'type':11s} {'lower':>10s} {'upper':>10s} {'effort':>10s} {'velocity':>10s}",
    ]
    if robot.floating_base:
        lines.append(f"{printable(robot.joints[0].name):30s} {'floating':11s} {'(base pose: x y z, quaternion x y z w)':>43s}")
    lower, upper = robot.physical_limits()
    open_limits = 0
    for index, joint in enumerate(robot.joints[1:] if robot.floating_base else robot.joints):
        position_unit, effort_unit, speed_unit = ("m", "N", "m/s") if joint.type == "prismatic" else ("rad", "N m", "rad/s")
        marks = [
            "*" if np.isfinite(given) and not np.isfinite(used) else ""
            for given, used in ((joint.lower, lower[index]), (joint.upper, upper[index]))
        ]
        marks += ["*" if given == 0 else "" for given in (joint.effort, joint.velocity)]
        open_limits += sum(bool(mark) for mark in marks)
        lines.append(
            f"{printable(joint.name):30s} {joint.type:11s} {_limit(joint.lower, position_unit) + marks[0]:>10s} "
            f"{_limit(joint.upper, position_unit) + marks[1]:>10s} {_limit(joint.effort, effort_unit) + marks[2]:>10s} "
            f"{_limit(joint.velocity, speed_unit) + marks[3]:>10s}"
        )
    if open_limits:
        lines.append("* a placeholder (|limit| ≥ 1e3, lower = upper, or 0 effort / velocity): treated as no limit")
    lines += ["", f"{'link':30s} {'mass':>12s}"]
    lines += [f"{printable(name):30s} {mass:>9.4g} kg" for name, mass in robot.link_masses.items()]
    lines.append(f"{'total':30s} {robot.total_mass:>9.4g} kg")
    return "\n".join(lines)


def _limit(value: float, unit: str) -> str:
    return "-" if not np.isfinite(value) else f"{value:.4g} {unit}"


def _vector(values: np.ndarray, precision: int) -> str:
    return "[" + ", ".join(f"{value:.{precision}g}" for value in values) + "]"


def _matrix(matrix: np.ndarray, precision: int) -> list[str]:
    width = precision + 7
    return ["  [" + " ".join(f"{value:{width}.{precision}g}" for value in row) + " ]" for row in matrix]


def equations_dict(robot: Robot, terms: DynamicsTerms) -> dict:
    """A JSON-ready record of the dynamics terms (keys ``tau``, ``M``, ``C``, ``G``, ...)."""
    return {
        "robot": robot.name,
        "joint_names": robot.joint_names,
        "equation": "tau = M(q) a + C(q, v) v + G(q)",
        "units": {**dof_units(robot), "M": "SI (kg m^2, kg m or kg by joint pair)", "C": "SI (M per second)"},
        "q": terms.q.tolist(),
        "v": terms.v.tolist(),
        "a": terms.a.tolist(),
        "tau": terms.tau.tolist(),
        "M": terms.M.tolist(),
        "C": terms.C.tolist(),
        "G": terms.G.tolist(),
    }


def equations_text(robot: Robot, terms: DynamicsTerms, *, precision: int = 6) -> str:
    """The dynamics terms as readable text, one block a term, with units."""
    units = dof_units(robot)
    lines = [f"{robot.name}: tau = M(q) a + C(q, v) v + G(q)", ""]
    header = f"{'joint':26s} {'q':>14s} {'v':>16s} {'a':>18s} {'tau':>16s} {'G':>16s}"
    lines.append(header)
    q_index = robot.nq - robot.nv  # a floating base has one more q than v entries
    for index, name in enumerate(robot.joint_names if not robot.floating_base else _dof_labels(robot)):
        q_value = terms.q[index + q_index] if index >= (6 if robot.floating_base else 0) else None
        q_unit = "m" if units["v"][index] == "m/s" else "rad"
        q_text = f"{q_value:.{precision}g} {q_unit}" if q_value is not None else "(base)"
        lines.append(
            f"{name:26s} {q_text:>14s} {terms.v[index]:>{10}.{precision}g} {units['v'][index]:5s} "
            f"{terms.a[index]:>{10}.{precision}g} {units['a'][index]:7s} {terms.tau[index]:>{11}.{precision}g} {units['tau'][index]:4s} "
            f"{terms.G[index]:>{11}.{precision}g} {units['tau'][index]:4s}"
        )
    lines += ["", "M(q), mass matrix (SI: kg m² between revolute joints, kg between prismatic, kg m mixed):"]
    lines += _matrix(terms.M, precision)
    lines += ["", "C(q, v), Coriolis matrix (SI: the units of M per second; C v is in the units of tau):"]
    lines += _matrix(terms.C, precision)
    return "\n".join(lines)


def _dof_labels(robot: Robot) -> list[str]:
    base = [f"base {axis}" for axis in ("vx", "vy", "vz", "wx", "wy", "wz")]
    return base + robot.joint_names[1:]


def _number(value: object, digits: int = 6) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return "unlimited" if not np.isfinite(value) else f"{value:.{digits}g}"


def simulation_text(summary: dict) -> str:
    """A simulation summary (from :func:`robodyn.sim.experiment.run_simulation`) as text.

    Numbers with six significant digits and their units; one line a limit violation.
    """
    from robodyn.sim.limits import LimitViolation

    units = summary.get("torque_units", [])
    names = [printable(name) for name in summary.get("dof_names", summary.get("joint_names", []))]
    lines = [
        f"robot: {printable(summary['robot'])}",
        f"controller: {summary['controller']} (integrator {summary['integrator']}, limits {summary['limits']})",
        f"simulated: {_number(summary['duration_s'])} s in {summary['steps']} steps of {_number(summary['dt_s'])} s"
        + (f", {_number(summary['real_time_factor'], 3)}× real time" if summary.get("real_time_factor") else ""),
    ]
    if "frame" in summary:
        lines += [
            f"frame: {printable(summary['frame'])}",
            f"target: {_vector(np.array(summary['target_m']), 6)} m",
            f"final position: {_vector(np.array(summary['final_position_m']), 6)} m",
            f"final error: {_number(summary['final_error_m'], 3)} m ({'reached' if summary['target_reached'] else 'NOT reached'})",
        ]
    if "final_joint_error" in summary:
        lines.append(f"final joint error: {_number(summary['final_joint_error'], 3)} (largest |q - target|, rad or m)")
    floating = any(name.startswith("base ") for name in names)
    q_units = "base position in m, quaternion x y z w, then joints in rad / m" if floating else "rad / m"
    lines.append(f"final q: {_vector(np.array(summary['final_q']), 6)} ({q_units})")
    peaks = [
        f"{name} {_number(peak, 4)} {unit}" for name, peak, unit in zip(names, summary["peak_abs_torque"], units, strict=False)
    ]
    lines.append(f"peak |torque|: {', '.join(peaks)}")
    lines.append(f"energy change: {_number(summary['energy_change_J'], 4)} J")
    violations = summary.get("limit_violations", [])
    if summary["limits"] == "ignore":
        lines.append("limits: not checked (--limits ignore)")
    elif not violations:
        lines.append("limits: every position, velocity and effort limit kept")
    for item in violations:
        fields = {**item, "first_time": item["first_time_s"]}
        del fields["first_time_s"]
        lines.append(f"limit violation: {LimitViolation(**fields).text()}")
    for key in ("trajectory", "plot", "recording", "poster"):
        if key in summary:
            lines.append(f"{key}: {summary[key]}")
    return "\n".join(lines)
