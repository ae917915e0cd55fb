"""A robot as an HTML table, for notebooks (``Robot._repr_html_``).

Pure: reads the robot, returns text. Every name from the URDF is HTML-escaped; units come
from the robot's degrees of freedom (:mod:`robodyn.dynamics.dofs`).
"""

from __future__ import annotations

import html
import math

from robodyn.exceptions import RobodynError


def _number(value: float | None, unit: str) -> str:
    if value is None or not math.isfinite(value):
        return "—"
    return f"{value:.4g} {unit}"


def robot_html(robot) -> str:
    """An HTML summary of a robot: name, degrees of freedom, mass, end effector, joints.

    Args:
        robot: A :class:`robodyn.Robot`.

    Returns:
        An HTML fragment: a heading line and a table of the joints (type, limits in [rad]
        or [m], effort limit in [N m] or [N], mass of the child link in [kg]).
    """
    escape = html.escape
    try:
        effector = escape(robot.end_effector)
    except RobodynError as error:  # no default end effector (several tips)
        effector = f"none ({escape(str(error))})"
    masses = robot.link_masses
    units = {dof.joint: dof for dof in robot.dofs if not dof.is_base}  # a joint's one degree of freedom
    rows = []
    for joint in robot.joints:
        spec = robot.spec.joints.get(joint.name)
        child = spec.child if spec is not None else robot.spec.root
        dof = units.get(joint.name)
        limit = f"{_number(dof.lower, dof.position_unit)} … {_number(dof.upper, dof.position_unit)}" if dof else "—"
        effort = _number(dof.effort_limit, dof.effort_unit) if dof else "—"
        rows.append(
            f"<tr><td>{escape(joint.name)}</td><td>{escape(joint.type)}</td><td>{limit}</td><td>{effort}</td>"
            f"<td>{escape(child)}</td><td>{_number(masses.get(child), 'kg')}</td></tr>"
        )
    return (
        f"<div><p><b>{escape(robot.name)}</b>: nq = {robot.nq}, nv = {robot.nv}, "
        f"{'floating' if robot.floating_base else 'fixed'} base, total mass {robot.total_mass:.4g} kg, "
        f"end effector <code>{effector}</code></p>"
        "<table><thead><tr><th>joint</th><th>type</th><th>position limits</th><th>effort limit</th>"
        "<th>child link</th><th>mass</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table></div>"
    )
