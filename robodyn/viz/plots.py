"""Figures (matplotlib PNG, headless): a simulation's story and the what-if sweep.

Every axis is labelled with its unit. Files are written atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from robodyn.common.files import atomic_write_bytes
from robodyn.dynamics.robot import Robot
from robodyn.sim.simulation import Trajectory


def _figure(rows: int, columns: int = 1, size: tuple[float, float] = (8.0, 9.0)):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(rows, columns, figsize=size, squeeze=False)


def _save(figure, path: str | Path) -> Path:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    figure.tight_layout()
    figure.savefig(buffer, format="png", dpi=110)
    plt.close(figure)
    return atomic_write_bytes(path, buffer.getvalue())


def _unit(robot: Robot, index: int, revolute: str, prismatic: str) -> str:
    joint = robot.joints[index] if index < len(robot.joints) else None
    return prismatic if joint is not None and joint.type == "prismatic" else revolute


def plot_simulation(
    robot: Robot, trajectory: Trajectory, path: str | Path, *, frame: str | None = None, target: np.ndarray | None = None
) -> Path:
    """Joint positions, torques, the frame's distance to its target, and energy over time."""
    figure, axes = _figure(4)
    t = trajectory.t
    offset = robot.nq - robot.nv
    for index, name in enumerate(robot.joint_names):
        if robot.joints[index].type == "floating":
            continue
        axes[0, 0].plot(t, trajectory.q[:, index + offset], label=f"{name} [{_unit(robot, index, 'rad', 'm')}]")
        axes[1, 0].plot(t, trajectory.tau[:, index + offset], label=f"{name} [{_unit(robot, index, 'N m', 'N')}]")
    axes[0, 0].set_ylabel("joint position [rad] / [m]")
    axes[1, 0].set_ylabel("joint torque [N m] / force [N]")
    for axis in axes[:2, 0]:
        axis.legend(fontsize="small", ncol=2)
    if frame is not None and target is not None:
        error = np.linalg.norm(robot.frame_position(trajectory.q, frame) - np.asarray(target), axis=1)
        axes[2, 0].semilogy(t, np.maximum(error, 1e-16))
        axes[2, 0].set_ylabel(f"|{frame} − target| [m]")
    else:
        axes[2, 0].text(0.5, 0.5, "no task-space target", ha="center", va="center", transform=axes[2, 0].transAxes)
    kinetic = robot.kinetic_energy(trajectory.q, trajectory.v)
    potential = robot.potential_energy(trajectory.q)
    axes[3, 0].plot(t, kinetic, label="kinetic")
    axes[3, 0].plot(t, potential, label="potential")
    axes[3, 0].plot(t, kinetic + potential, label="total", color="black")
    axes[3, 0].set_ylabel("energy [J]")
    axes[3, 0].set_xlabel("time [s]")
    axes[3, 0].legend(fontsize="small")
    axes[0, 0].set_title(f"{robot.name}: simulation")
    return _save(figure, path)


def plot_whatif(rows, joint_names: list[str], units: list[str], path: str | Path) -> Path:
    """Peak and RMS torque of each joint, one bar a variant (material, payload, force)."""
    figure, axes = _figure(len(joint_names), 1, (9.0, 3.2 * len(joint_names)))
    labels = [
        f"{r.material}\n{r.payload:g} kg" + (f"\nF={','.join(f'{f:g}' for f in r.force)}" if np.any(r.force) else "")
        for r in rows
    ]
    positions = np.arange(len(rows))
    for index, (name, unit) in enumerate(zip(joint_names, units, strict=True)):
        axis = axes[index, 0]
        axis.bar(positions - 0.2, [r.peak[index] for r in rows], width=0.4, label="peak |torque|")
        axis.bar(positions + 0.2, [r.rms[index] for r in rows], width=0.4, label="RMS torque")
        axis.set_xticks(positions, labels, fontsize="x-small")
        axis.set_ylabel(f"{name} [{unit}]")
        axis.legend(fontsize="small")
    axes[0, 0].set_title("What if: link material and payload over one motion")
    return _save(figure, path)
