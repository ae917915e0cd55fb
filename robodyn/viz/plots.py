"""Figures (matplotlib, headless): a simulation's story and the what-if sweep.

Each figure is a :class:`matplotlib.figure.Figure` on its own Agg canvas, made with the
object-oriented API: no global matplotlib state (backend, ``pyplot`` figures) is touched,
so the figures are safe inside notebooks and other programs. ``*_figure`` functions return
the figure (to show inline or inspect); ``plot_*`` write it as a PNG, atomically.

Conventions:
    - one axis a quantity and unit: positions in [rad] (revolute, continuous joints) and
      [m] (prismatic joints, the floating base), torques in [N m] and forces in [N];
    - a joint has one colour in every panel; the legend sits outside the data;
    - position and effort limits are drawn as a light band in the joint's colour (with
      dashed edges), and the axis is widened to show a limit close to the motion;
    - :func:`text_overlaps` (:mod:`robodyn.viz.layout`, re-exported here) finds text that
      collides or leaves the figure (the tests run it on every figure;
      :func:`whatif_figure` uses it to tilt crowded tick labels).
"""

from __future__ import annotations

import io
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from robodyn.common.files import atomic_write_bytes
from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import ViewerError
from robodyn.trajectory import Trajectory
from robodyn.viz.layout import text_boxes as text_boxes  # re-exported
from robodyn.viz.layout import text_overlaps

DPI = 110
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def text_label(name: str) -> str:
    """A name as matplotlib draws it literally: ``$`` escaped (no mathtext), control characters as ``?``.

    Args:
        name: A joint's or frame's name (from the robot's file).
    """
    return _CONTROL.sub("?", str(name)).replace("$", r"\$")


def new_figure(width: float, height: float) -> Figure:
    """A figure with constrained layout on its own Agg canvas.

    Args:
        width: In [inch].
        height: In [inch].
    """
    figure = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def save_png(figure: Figure, path: str | Path) -> Path | None:
    """Write a figure as PNG, atomically; the file written, ``None`` for standard output (``-``).

    Args:
        figure: The figure.
        path: The PNG file, or ``-`` for standard output.
    """
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    return atomic_write_bytes(path, buffer.getvalue())


# --------------------------------------------------------------------------------------
# Limits
# --------------------------------------------------------------------------------------
def _band(axis: Axes, lower: float, upper: float, color, alpha: float) -> None:
    if not (np.isfinite(lower) or np.isfinite(upper)):
        return
    low = lower if np.isfinite(lower) else -1e300
    high = upper if np.isfinite(upper) else 1e300
    axis.axhspan(low, high, color=color, alpha=alpha, linewidth=0, zorder=0)
    for edge in (lower, upper):
        if np.isfinite(edge):
            axis.axhline(edge, color=color, linestyle="--", linewidth=0.8, alpha=0.7, zorder=1)


def _fit(axis: Axes, data: list[np.ndarray], limits: list[float]) -> None:
    """Y range: the data with a margin, widened to a limit within a quarter span of it."""
    values = np.concatenate([np.ravel(d) for d in data])
    values = values[np.isfinite(values)]
    if values.size == 0:
        return
    low, high = float(values.min()), float(values.max())
    span = max(high - low, 0.05 * max(abs(low), abs(high)), 0.02)
    for limit in limits:
        if np.isfinite(limit) and low - 0.25 * span <= limit <= high + 0.25 * span:
            low, high = min(low, limit), max(high, limit)
    span = max(high - low, span)
    axis.set_ylim(low - 0.08 * span, high + 0.08 * span)


# --------------------------------------------------------------------------------------
# The simulation figure
# --------------------------------------------------------------------------------------
def simulation_figure(
    robot: Robot,
    trajectory: Trajectory,
    *,
    frame: str | None = None,
    target: np.ndarray | None = None,
    panels: Sequence[Any] = (),
) -> Figure:
    """Joint positions, joint torques / forces, the frame's distance to its target, energy.

    Args:
        robot: The robot the trajectory belongs to.
        trajectory: ``t`` in [s]; ``q`` shape (N, nq); ``v``, ``tau`` shape (N, nv).
        frame: With ``target``: the frame whose distance to the target is drawn.
        target: Target position in [m], shape (3,).
        panels: More panels before the energy's, each a
            :class:`~robodyn.sim.drawings.PlotPanel` (commanded vs measured force, ...).

    Returns:
        The figure: one panel a quantity and unit; revolute and prismatic joints apart.
    """
    extra, panels = tuple(panels), _joint_panels(robot)
    task = frame is not None and target is not None
    rows = len(panels) + 1 + int(task) + len(extra)
    figure = new_figure(9.0, 1.9 * rows + 0.6)
    axes = figure.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    joints = [dof for dof in robot.dofs if not dof.is_base]
    colors = {dof.name: f"C{i % 10}" for i, dof in enumerate(joints)}
    for axis, (ylabel, group) in zip(axes, panels, strict=False):
        _joint_panel(axis, robot, trajectory, ylabel, group, colors)
    row = len(panels)
    if frame is not None and target is not None:  # the task panel
        error = np.linalg.norm(robot.frame_position(trajectory.q, frame) - np.asarray(target, dtype=float), axis=1)
        axes[row].semilogy(trajectory.t, np.maximum(error, 1e-16), color="tab:red", label=f"|{text_label(frame)} − target|")
        axes[row].set_ylabel("distance [m]")
        axes[row].grid(alpha=0.3, which="both")
        row += 1
    for axis, panel in zip(axes[row:-1], extra, strict=True):
        _curves_panel(axis, panel)
    _energy_panel(axes[-1], robot, trajectory)
    axes[-1].set_xlabel("time [s]")
    # One legend for the joints (a colour each, shared by every panel), one for the rest.
    handles, labels = [], []
    for axis in axes:
        for handle, label in zip(*axis.get_legend_handles_labels(), strict=True):
            if label not in labels:
                handles.append(handle)
                labels.append(label)
    figure.legend(handles, labels, loc="outside right upper", fontsize="small", title="shaded: limits", title_fontsize="small")
    figure.suptitle(f"{text_label(robot.name)}: simulation, {trajectory.t[-1] - trajectory.t[0]:.3g} s")
    return figure


def _joint_panels(robot: Robot) -> list[tuple[str, list[Dof]]]:
    """The joint panels, one a quantity and unit: (y label, the joints drawn in it)."""
    joints = [dof for dof in robot.dofs if not dof.is_base]
    angular = [dof for dof in joints if not dof.linear]
    linear = [dof for dof in joints if dof.linear]
    panels: list[tuple[str, list[Dof]]] = []
    if angular:
        panels.append(("position [rad]", angular))
    if linear or robot.floating_base:
        panels.append(("position [m]", linear))
    if angular:
        panels.append(("torque [N m]", angular))
    if linear:
        panels.append(("force [N]", linear))
    return panels


def _joint_panel(axis: Axes, robot: Robot, trajectory: Trajectory, ylabel: str, group: list[Dof], colors: dict[str, str]) -> None:
    """The positions or efforts of ``group`` over time, each with its limits shaded (and, in
    the panel of lengths of a floating-base robot, the base's position)."""
    effort = ylabel.startswith(("torque", "force"))
    q_offset = robot.nq - robot.nv  # a floating base's quaternion: one q more than v
    t = trajectory.t
    data, limits = [], []
    for dof in group:
        torques = trajectory.tau if trajectory.tau is not None else np.zeros_like(trajectory.v)
        column = torques[:, dof.index] if effort else trajectory.q[:, dof.index + q_offset]
        axis.plot(t, column, color=colors[dof.name], label=text_label(dof.name), linewidth=1.3)
        low, high = (-dof.effort_limit, dof.effort_limit) if effort else (dof.lower, dof.upper)
        _band(axis, low, high, colors[dof.name], min(0.07, 0.2 / len(group)))
        data.append(column)
        limits += [low, high]
    if ylabel == "position [m]" and robot.floating_base:
        for k, style in enumerate((":", "-.", "--")):
            column = trajectory.q[:, k]
            axis.plot(t, column, color="0.3", linestyle=style, label=robot.configuration_names[k], linewidth=1.3)
            data.append(column)
    _fit(axis, data, limits)
    axis.set_ylabel(ylabel)
    axis.grid(alpha=0.3)


def _curves_panel(axis: Axes, panel: Any) -> None:
    """A :class:`~robodyn.sim.drawings.PlotPanel`: its curves, one colour and style each."""
    for index, (label, t, values, style) in enumerate(panel.curves):
        colour = ("darkred", "darkgreen", "navy", "darkorange")[index % 4]
        axis.plot(t, values, color=colour, linestyle=style, label=text_label(label), linewidth=1.3)
    axis.set_ylabel(panel.ylabel)
    axis.ticklabel_format(axis="y", useOffset=False)  # a force held to 1e-5 N: its values, not an offset
    axis.grid(alpha=0.3)


def _energy_panel(axis: Axes, robot: Robot, trajectory: Trajectory) -> None:
    """Kinetic, potential and total energy in [J] over time."""
    kinetic = np.atleast_1d(robot.kinetic_energy(trajectory.q, trajectory.v))
    potential = np.atleast_1d(robot.potential_energy(trajectory.q))
    axis.plot(trajectory.t, kinetic, label="kinetic", color="black", linestyle="--")
    axis.plot(trajectory.t, potential, label="potential", color="black", linestyle=":")
    axis.plot(trajectory.t, kinetic + potential, label="total", color="black")
    axis.set_ylabel("energy [J]")
    axis.grid(alpha=0.3)


def plot_simulation(
    robot: Robot,
    trajectory: Trajectory,
    path: str | Path,
    *,
    frame: str | None = None,
    target: np.ndarray | None = None,
    panels: Sequence[Any] = (),
) -> Path | None:
    """Write :func:`simulation_figure` as a PNG (atomically) and return its path (``None`` for ``-``).

    Args:
        path: The PNG file, or ``-`` for standard output; the other arguments are
            :func:`simulation_figure`'s.
    """
    return save_png(simulation_figure(robot, trajectory, frame=frame, target=target, panels=panels), path)


# --------------------------------------------------------------------------------------
# The what-if figure
# --------------------------------------------------------------------------------------
def whatif_figure(rows, joint_names: list[str], units: list[str], *, effort_limits: list[float] | None = None) -> Figure:
    """Peak and RMS effort of each joint, a pair of bars a variant (material, payload, force).

    Args:
        rows: :class:`robodyn.sim.whatif.Variant` rows (``peak``, ``rms`` shape (nv,)).
        joint_names: One name a column of ``peak``.
        units: ``"N m"`` (a torque) or ``"N"`` (a force) a column.
        effort_limits: Effort limit a column, drawn as a dashed red line when finite. Each
            axis is scaled to the bars; a limit at most half again above the tallest bar
            widens it, a limit far above them (a kuka's 300 N m over bars of 10 N m) is
            named at the top edge instead, so the bars stay readable.
    """
    if len(joint_names) != len(units) or any(len(r.peak) != len(units) for r in rows):
        raise ViewerError(
            f"the what-if plot needs one joint name a unit and a column: {len(joint_names)} names, {len(units)} units."
        )
    labels = [
        f"{r.material}\n{r.payload:g} kg" + (f"\nF={','.join(f'{f:g}' for f in r.force)} N" if np.any(r.force) else "")
        for r in rows
    ]
    count = len(joint_names)
    figure = new_figure(min(max(7.0, 0.75 * len(rows) + 3.5), 12.0), 2.2 * count + 1.4)
    axes = figure.subplots(count, 1, sharex=True, squeeze=False)[:, 0]
    positions = np.arange(len(rows))
    for index, (name, unit) in enumerate(zip(joint_names, units, strict=True)):
        axis = axes[index]
        word = "force" if unit == "N" else "torque"
        axis.bar(positions - 0.2, [r.peak[index] for r in rows], width=0.4, color="C0", label="peak |effort|")
        axis.bar(positions + 0.2, [r.rms[index] for r in rows], width=0.4, color="C1", label="RMS effort")
        limit = effort_limits[index] if effort_limits is not None else np.inf
        _whatif_limit(axis, max([*(r.peak[index] for r in rows), *(r.rms[index] for r in rows)], default=0.0), limit, unit)
        axis.set_ylabel(f"{text_label(name)}\n{word} [{unit}]")
        axis.grid(axis="y", alpha=0.3)
    axes[-1].set_xticks(positions, labels, fontsize="small")
    handles, legend_labels = [], []
    for axis in axes:
        for handle, label in zip(*axis.get_legend_handles_labels(), strict=True):
            if label not in legend_labels:
                handles.append(handle)
                legend_labels.append(label)
    figure.legend(handles, legend_labels, loc="outside right center", fontsize="small")
    figure.suptitle("What if: link material, payload and force, over one motion")
    for angle in (45, 90):  # crowded: one line a label, tilted
        if not any("tick" in a and "tick" in b for a, b in text_overlaps(figure)):
            break
        axes[-1].set_xticks(positions, [label.replace("\n", ", ") for label in labels], fontsize="small")
        for label in axes[-1].get_xticklabels():
            label.set(rotation=angle, horizontalalignment="right", rotation_mode="anchor")
    return figure


def _whatif_limit(axis: Axes, top: float, limit: float, unit: str) -> None:
    """Scale a what-if axis to its bars (highest ``top``) and draw the effort ``limit``:
    a dashed line when near the bars, else a note at the top edge."""
    top = float(top) if np.isfinite(top) and top > 0 else 1.0
    near = np.isfinite(limit) and 0 < limit <= 1.5 * top
    high = 1.08 * max(top, limit) if near else 1.15 * top
    axis.set_ylim(0.0, high)
    if near:
        axis.axhline(limit, color="red", linestyle="--", linewidth=1.0, label="effort limit")
    elif np.isfinite(limit) and limit > 0:
        axis.plot([], [], color="red", linestyle="--", linewidth=1.0, label="effort limit")  # legend entry
        axis.annotate(
            f"limit {limit:g} {unit} (above)", xy=(1.0, 1.0), xycoords="axes fraction", xytext=(-4, -4),
            textcoords="offset points", ha="right", va="top", color="red", fontsize="small",
        )  # fmt: skip


def plot_whatif(rows, joint_names: list[str], units: list[str], path: str | Path, **options) -> Path | None:
    """Write :func:`whatif_figure` as a PNG (atomically) and return its path (``None`` for ``-``).

    Args:
        path: The PNG file, or ``-`` for standard output; the other arguments are
            :func:`whatif_figure`'s.
    """
    return save_png(whatif_figure(rows, joint_names, units, **options), path)


def external_torques_figure(
    t: np.ndarray,
    estimate: np.ndarray,
    applied: np.ndarray | None,
    dof_names: list[str] | tuple[str, ...],
    units: list[str] | tuple[str, ...],
    *,
    gain: float | None = None,
) -> Figure:
    """The observer's estimate of the external torques against those applied, over time.

    One panel a unit ([N m] for revolute joints, [N] for prismatic ones); a joint has one
    colour: solid its estimate, dashed the applied torque (when known).

    Args:
        t: Times in [s], shape (N,).
        estimate: Estimated external torques, shape (N, nv).
        applied: Applied external torques, shape (N, nv), or ``None``.
        dof_names, units: Names and torque units of the nv coordinates.
        gain: The observer's gain in [1/s], for the title.
    """
    kinds = list(dict.fromkeys(units))
    figure = new_figure(9.0, 2.6 * len(kinds) + 0.6)
    axes = figure.subplots(len(kinds), 1, sharex=True, squeeze=False)[:, 0]
    colors = {name: f"C{index % 10}" for index, name in enumerate(dof_names)}
    for axis, unit in zip(axes, kinds, strict=True):
        for index, name in enumerate(dof_names):
            if units[index] != unit:
                continue
            axis.plot(t, estimate[:, index], color=colors[name], label=f"{text_label(name)} estimated")
            if applied is not None:
                axis.plot(t, applied[:, index], color=colors[name], linestyle="--", label=f"{text_label(name)} applied")
        axis.set_ylabel(f"external [{unit}]")
        axis.grid(alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    axes[-1].set_xlabel("time [s]")
    title = (
        "external torques: observer estimate (solid) vs applied (dashed)"
        if applied is not None
        else "external torques: observer estimate"
    )
    figure.suptitle(title + (f", gain {gain:g} /s" if gain else ""), fontsize=10)
    return figure


def plot_external_torques(
    t: np.ndarray,
    estimate: np.ndarray,
    applied: np.ndarray | None,
    dof_names: list[str] | tuple[str, ...],
    units: list[str] | tuple[str, ...],
    path: str | Path,
    *,
    gain: float | None = None,
) -> Path | None:
    """Write :func:`external_torques_figure` as a PNG (atomically); ``None`` for ``-``.

    Args:
        path: The PNG file, or ``-`` for standard output; the other arguments are
            :func:`external_torques_figure`'s.
    """
    return save_png(external_torques_figure(t, estimate, applied, dof_names, units, gain=gain), path)
