"""The columns of a trajectory file: names, layout and checks.

The format itself is described in :mod:`robodyn.trajectory` and
``docs/trajectory-format.md``; this module names the coordinates (a floating base's by
:data:`robodyn.dynamics.dofs.BASE_Q_NAMES` / :data:`~robodyn.dynamics.dofs.BASE_V_NAMES`),
turns a header into a :class:`Layout` (every error names the columns) and refuses NaN/inf
and non-increasing time with the row.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.dofs import BASE_Q_NAMES, BASE_V_NAMES
from robodyn.exceptions import TrajectoryError

#: The name robodyn's loader gives a floating base's joint (first of ``Robot.joint_names``).
ROOT_JOINT = "root_joint"
#: Kinds of columns, in the order a table has them: positions, velocities, accelerations, torques.
KINDS = ("q", "v", "a", "tau")
#: Columns a file may add besides the trajectory's own; read back as a trajectory, they are
#: skipped (:func:`extra_columns` reads them): gravity torques and mass-matrix entries
#: (``robodyn torques``), the external torques an observer estimated (``tau_ext``: the
#: residual of :class:`robodyn.sim.observer.MomentumObserver`, ``robodyn simulate
#: --observer-gain``) and those the environment applied (``tau_env``: ``J(q)ᵀ w`` of the
#: pushes of ``robodyn simulate --force-at``), in [N m] / [N], named as ``v``.
EXTRA_KINDS = ("G", "M", "tau_ext", "tau_env")
_COLUMN = re.compile(r"^(q|v|a|tau)\[(.*)\]$", re.DOTALL)
_EXTRA = re.compile(r"^(G|M|tau_ext|tau_env)\[(.*)\]$", re.DOTALL)
#: A contact simulation's columns (:func:`contact_header`), skipped on reading as a trajectory:
#: each contact's force on the robot in world axes ``f[<contact>].x/.y/.z`` [N] and whether
#: it pushes, ``contact[<contact>]`` (1 or 0); a controlled run adds the force its controller
#: commanded beside it, ``f_cmd[<contact>].x/.y/.z`` [N] (:func:`commanded_header`).
_CONTACT = re.compile(r"^(f(_cmd)?\[(.*)\]\.[xyz]|contact\[(.*)\])$", re.DOTALL)
#: A constrained simulation's multipliers (:func:`constraint_header`), skipped on reading as a
#: trajectory: ``lambda[<constraint>].x/.y/.z`` [N] (and a weld's ``.mx/.my/.mz`` [N m], a
#: sliding contact's ``.n`` [N]), world axes.
_CONSTRAINT = re.compile(r"^lambda\[(.*)\]\.(x|y|z|mx|my|mz|n)$", re.DOTALL)
_LEGACY_Q = re.compile(r"^q(\d+)$")


def coordinate_names(joint_names: list[str], floating_base: bool) -> tuple[list[str], list[str]]:
    """Names of the configuration and velocity coordinates (what goes in the brackets).

    Args:
        joint_names: ``Robot.joint_names`` (a floating base's root joint first).
        floating_base: Whether the first joint is a free-flyer.

    Returns:
        ``(q_names, v_names)`` of lengths nq and nv.
    """
    if floating_base:
        joints = list(joint_names[1:])
        return [*BASE_Q_NAMES, *joints], [*BASE_V_NAMES, *joints]
    return list(joint_names), list(joint_names)


def coordinate_names_to_joints(v_names: list[str], floating_base: bool) -> list[str]:
    """``Robot.joint_names`` from velocity coordinate names (inverse of :func:`coordinate_names`).

    Args:
        v_names: The velocity coordinates' names (a floating base's six first).
        floating_base: Whether the first joint is a free-flyer.
    """
    return [ROOT_JOINT, *v_names[len(BASE_V_NAMES) :]] if floating_base else list(v_names)


def contact_header(contacts: list[str]) -> list[str]:
    """The columns of a contact simulation's forces and active flags, for contacts named
    ``contacts``: ``f[<c>].x``, ``f[<c>].y``, ``f[<c>].z`` of each, then ``contact[<c>]``.

    Args:
        contacts: The contacts' names.
    """
    forces = [f"f[{name}].{axis}" for name in contacts for axis in "xyz"]
    return forces + [f"contact[{name}]" for name in contacts]


def commanded_header(contacts: list[str]) -> list[str]:
    """The columns of the contact forces a controller commanded, world axes, in [N]:
    ``f_cmd[<c>].x``, ``f_cmd[<c>].y``, ``f_cmd[<c>].z`` of each contact.

    Args:
        contacts: The contacts' names.
    """
    return [f"f_cmd[{name}].{axis}" for name in contacts for axis in "xyz"]


def contact_columns(header: list[str], table: np.ndarray, contacts: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """A table's contact forces (N, k, 3) [N] and active flags (N, k) (:func:`contact_header`).

    Args:
        header: The table's column names.
        table: The table, one sample a row, shape (N, columns).
        contacts: The contacts' names.

    Raises:
        TrajectoryError: When a column of those contacts is missing.
    """
    names = contact_header(contacts)
    missing = [name for name in names if name not in header]
    if missing:
        raise TrajectoryError("the table", f"missing columns {short_list(missing)}")
    values = np.asarray(table, dtype=float)[:, [header.index(name) for name in names]]
    count = len(contacts)
    return values[:, : 3 * count].reshape(len(values), count, 3), values[:, 3 * count :] > 0.5


def constraint_header(labels: Sequence[tuple[str, str, str]]) -> list[str]:
    """The columns of a constrained simulation's multipliers: ``lambda[<constraint>].<component>``
    for each ``(constraint, component, unit)`` row (:func:`robodyn.constraints.algebra.row_labels`).

    Args:
        labels: The rows of ``λ``.
    """
    return [f"lambda[{name}].{component}" for name, component, _ in labels]


def constraint_columns(header: list[str], table: np.ndarray, labels: Sequence[tuple[str, str, str]]) -> np.ndarray:
    """A table's multipliers (N, m) in [N] / [N m] (:func:`constraint_header`).

    Args:
        header: The table's column names.
        table: Its rows, shape (N, len(header)).
        labels: The rows of ``λ`` to read.

    Raises:
        TrajectoryError: When a column of those rows is missing.
    """
    names = constraint_header(labels)
    missing = [name for name in names if name not in header]
    if missing:
        raise TrajectoryError("the table", f"missing columns {short_list(missing)}")
    return np.asarray(table, dtype=float)[:, [header.index(name) for name in names]]


def short_list(names: list[str], limit: int = 4) -> str:
    """The first ``limit`` names (escaped), and how many more.

    Args:
        names: The names.
        limit: How many to show.
    """
    shown = ", ".join(printable(name) for name in names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


@dataclass(frozen=True)
class Layout:
    """Where each kind of column is in a table (from a header).

    Attributes:
        q_names: Configuration coordinate names (nq), in file order of the joints.
        v_names: Velocity coordinate names (nv).
        time: Index of the ``t`` column.
        columns: Kind -> column indices in coordinate order, or ``None`` when absent.
        floating_base: Whether the table has the seven base coordinates.
    """

    q_names: tuple[str, ...]
    v_names: tuple[str, ...]
    time: int
    columns: dict[str, np.ndarray | None]
    floating_base: bool
    header: tuple[str, ...] = ()

    @property
    def width(self) -> int:
        """Number of columns a row has."""
        return len(self.header)

    @property
    def joint_names(self) -> list[str]:
        """``Robot.joint_names`` of the robot this layout belongs to."""
        return coordinate_names_to_joints(list(self.v_names), self.floating_base)


def parse_header(header: list[str], source: str, *, width: int | None = None) -> Layout:
    """The :class:`Layout` of a header (column names), with every error named.

    Args:
        header: Column names, e.g. ``["t", "q[j1]", "v[j1]"]``.
        source: The file, for messages.
        width: Number of values a data row has, if known (reads robodyn 0.1 floating files).

    Raises:
        TrajectoryError: Naming the missing, duplicated, unknown or extra columns.
    """
    header = [name.strip() for name in header]
    if width is not None and width != len(header):
        header = _legacy_header(header, width, source)
    duplicates = sorted({name for name in header if header.count(name) > 1})
    if duplicates:
        raise TrajectoryError(source, f"duplicated columns {short_list(duplicates)}")
    found: dict[str, dict[str, int]] = {kind: {} for kind in KINDS}
    unknown = []
    for index, name in enumerate(header):
        match = _COLUMN.match(name)
        if match:
            found[match.group(1)][match.group(2)] = index
        elif name != "t" and not _EXTRA.match(name) and not _CONTACT.match(name) and not _CONSTRAINT.match(name):
            unknown.append(name)
    if unknown:
        raise TrajectoryError(
            source, f"unknown columns {short_list(unknown)} (expected t, q[<joint>], v[<joint>], a[<joint>], tau[<joint>])"
        )
    if "t" not in header:
        count = len(found["q"]) or len(header)
        raise TrajectoryError(source, f"no 't' column (time in [s]); the file has {count} q columns, and t must be one of them")
    if not found["q"]:
        raise TrajectoryError(source, "no q[<joint>] columns (joint positions)")
    q_names = list(found["q"])
    base = [name for name in q_names if name.startswith("base.")]
    floating = any(name in BASE_Q_NAMES for name in base)
    if floating:
        missing = [f"q[{name}]" for name in BASE_Q_NAMES if name not in found["q"]]
        if missing:
            raise TrajectoryError(source, f"missing columns {short_list(missing)} (a floating base has 7 coordinates)")
    joints = [name for name in q_names if not (floating and name in BASE_Q_NAMES)]
    q_names = [*BASE_Q_NAMES, *joints] if floating else joints
    v_names = [*BASE_V_NAMES, *joints] if floating else joints
    columns: dict[str, np.ndarray | None] = {"q": np.array([found["q"][name] for name in q_names])}
    for kind in ("v", "a", "tau"):
        present = found[kind]
        if not present:
            columns[kind] = None
            continue
        missing = [f"{kind}[{name}]" for name in v_names if name not in present]
        extra = [f"{kind}[{name}]" for name in present if name not in v_names]
        if extra:
            raise TrajectoryError(source, f"columns {short_list(extra)} have no matching q column")
        if missing:
            raise TrajectoryError(source, f"missing columns {short_list(missing)}")
        columns[kind] = np.array([present[name] for name in v_names])
    return Layout(tuple(q_names), tuple(v_names), header.index("t"), columns, floating, tuple(header))


def _legacy_header(header: list[str], width: int, source: str) -> list[str]:
    """A robodyn 0.1 floating-base header (``q0 ... q<nq-1>``, one v name for the base)."""
    nq = sum(bool(_LEGACY_Q.match(name)) for name in header)
    names = [name[2:-1] for name in header if name.startswith("v[")]
    if nq and names and (width - 1 - nq) % 3 == 0:
        nv = (width - 1 - nq) // 3
        if nv == len(names) + 5 and nq == nv + 1:
            q_names, v_names = coordinate_names(names, True)
            return ["t"] + [f"q[{n}]" for n in q_names] + [f"{kind}[{n}]" for kind in ("v", "a", "tau") for n in v_names]
    raise TrajectoryError(source, f"the header names {len(header)} columns but the rows have {width} values")


def check_table(
    table: np.ndarray, layout: Layout, source: str, *, first_row: int = 1, previous_time: float | None = None
) -> None:
    """Refuse NaN, inf and non-increasing time, naming the row (1-based data rows).

    Args:
        table: Rows of values, shape (N, width).
        layout: Its columns.
        source: The file, for messages.
        first_row: Data row number of ``table[0]`` (for chunks of a larger file).
        previous_time: Time of the row before ``table[0]``, if any.

    Raises:
        TrajectoryError: Naming the file, the row and the column.
    """
    finite = np.isfinite(table)
    if not finite.all():
        row, column = np.argwhere(~finite)[0]
        name = layout.header[column] if column < len(layout.header) else f"column {column + 1}"
        raise TrajectoryError(source, f"{name} is {table[row, column]} (values must be finite)", rows=(first_row + row,) * 2)
    times = table[:, layout.time]
    if previous_time is not None:
        times = np.concatenate([[previous_time], times])
        first_row -= 1
    steps = np.diff(times)
    if (steps <= 0).any():
        row = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise TrajectoryError(
            source, f"time does not increase (t = {times[row]!r} after {times[row - 1]!r})", rows=(first_row + row,) * 2
        )


def extra_columns(table: np.ndarray, layout: Layout, kind: str) -> np.ndarray | None:
    """The columns of an extra kind (``tau_ext``, ``tau_env``, ``G``), in ``v``'s order.

    Args:
        table: Rows of values, shape (N, layout.width).
        layout: Its columns (:func:`parse_header`).
        kind: One of :data:`EXTRA_KINDS` named like ``v`` (not ``M``).

    Returns:
        Shape (N, nv), or ``None`` when the table has no column of that kind.

    Raises:
        TrajectoryError: When some but not all of the kind's columns are present.
    """
    names = [f"{kind}[{name}]" for name in layout.v_names]
    present = [name for name in names if name in layout.header]
    if not present:
        return None
    if len(present) != len(names):
        missing = [name for name in names if name not in layout.header]
        raise TrajectoryError("the table", f"missing columns {short_list(missing)}")
    return np.asarray(table, dtype=float)[:, [layout.header.index(name) for name in names]]
