"""Experiments with their files: a simulation run, and the what-if table.

:func:`run_experiment` is :func:`robodyn.sim.experiment.run_simulation` plus the files a
run is asked to write, all of them or none (:func:`robodyn.common.files.outputs_together`);
the summary it returns names each file written (``robodyn simulate``).
:func:`run_whatif` is :func:`robodyn.sim.whatif.what_if`, locally or on Dask, plus its bar
chart (``robodyn whatif``).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.common.files import outputs_together
from robodyn.dynamics.robot import Robot
from robodyn.sim.experiment import run_simulation
from robodyn.sim.report import SimulationSummary
from robodyn.sim.whatif import WhatIfTable, what_if

PathLike = str | Path


def run_experiment(
    robot: Robot,
    *,
    out: PathLike | None = None,
    plot: PathLike | None = None,
    record: PathLike | None = None,
    png: PathLike | None = None,
    **settings: Any,
) -> SimulationSummary:
    """Simulate (``settings``: as for :func:`~robodyn.sim.experiment.run_simulation`) and
    write the files asked for.

    Args:
        robot: The plant.
        out: Trajectory file (``.csv`` or ``.npz``).
        plot: PNG figure: positions, torques, task error, energy.
        record: Self-contained HTML animation (meshcat).
        png: With ``record``: a still of the first frame (needs Chromium).
        **settings: ``controller``, ``target``, ``frame``, ``q0``, ``duration``, ``dt``,
            ``integrator``, ``limits``, ``engine``.

    Returns:
        The run's summary; its ``files`` name what was written (``trajectory``, ``plot``,
        ``recording``, ``poster``).
    """
    trajectory, summary = run_simulation(robot, **settings)
    frame = summary.task.frame if summary.task is not None else None
    task = np.asarray(summary.task.target) if summary.task is not None else None
    with outputs_together():  # every file of the run, or none of them
        if out:
            summary = summary.with_file("trajectory", str(trajectory.save(out)))
        if plot:
            from robodyn.viz.plots import plot_simulation  # matplotlib: only when a figure is asked for

            summary = summary.with_file("plot", str(plot_simulation(robot, trajectory, plot, frame=frame, target=task)))
        if record:
            from robodyn.viz.recording import record as write_recording  # meshcat: only for an animation

            written = write_recording(robot, trajectory, record, png=png, target=task, frame=frame or robot.end_effector)
            summary = summary.with_file("recording", str(written))
            if png:
                summary = summary.with_file("poster", str(png))
    return summary


def run_whatif(
    model: str = "rp_arm", *, scheduler: str | None = None, plot: PathLike | None = None, **options: Any
) -> WhatIfTable:
    """The what-if table of ``model`` (``options``: as for :func:`~robodyn.sim.whatif.what_if`).

    Args:
        model: ``"rp_arm"`` (materials apply) or any robot :func:`robodyn.load` takes.
        scheduler: Compute the rows on Dask: a scheduler address or ``local:N``
            (:func:`robodyn.scale.cluster.connect`); ``None``: here.
        plot: PNG bar chart of the table.
        **options: ``materials``, ``payloads``, ``forces``, ``q_start``, ``q_end``,
            ``duration``, ``frame``.
    """
    if scheduler:
        from robodyn.scale.cluster import connect  # Dask: only when asked for
        from robodyn.scale.sweeps import what_if as distributed_what_if

        with connect(scheduler) as client:
            table = distributed_what_if(model, client=client, **options)
    else:
        table = what_if(model, **options)
    if plot:
        from robodyn.viz.plots import plot_whatif  # matplotlib: only when a figure is asked for

        rows, limits = list(table.rows), [float(e) for e in table.rows[0].effort]
        plot_whatif(rows, list(table.joint_names), list(table.torque_units), plot, effort_limits=limits)
        table = replace(table, plot=str(plot))
    return table
