"""Experiments with their files: a simulation run, a recording, and the what-if table.

:func:`run_experiment` is :func:`robodyn.sim.experiment.run_simulation` plus the files a
run is asked to write, all of them or none (:func:`robodyn.common.files.outputs_together`);
the summary it returns names each file written (``robodyn simulate``).
:func:`run_whatif` is :func:`robodyn.sim.whatif.what_if`, locally or on Dask, plus its bar
chart (``robodyn whatif``). :func:`record_files` draws a trajectory and writes its HTML
animation, stills and videos (``robodyn record``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.common.files import outputs_together
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.experiment import applied_torques, push_wrenches
from robodyn.sim.hybrid_run import run_named
from robodyn.sim.observer import ObservationRun, observe_file
from robodyn.sim.operational_space import target_rotation
from robodyn.sim.report import SimulationSummary
from robodyn.sim.whatif import WhatIfTable, what_if
from robodyn.trajectory import Trajectory
from robodyn.trajectory.io import write_with_extras

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
    """Simulate (``settings``: as for :func:`~robodyn.sim.experiment.run_simulation`, or
    :func:`~robodyn.sim.hybrid_run.run_hybrid` for ``controller="hybrid"``) and write the files asked for.

    Args:
        robot: The plant.
        out: Trajectory file (``.csv`` or ``.npz``; a run on the ground: ``.csv``, with its
            contact forces, docs/contact.md).
        plot: PNG figure: positions, torques, task error, energy.
        record: Self-contained HTML animation (meshcat).
        png: With ``record``: a poster, the final frame with the path drawn (needs Chromium).
        **settings: ``controller``, ``target``, ``frame``, ``q0``, ``duration``, ``dt``,
            ``integrator``, ``limits``, ``engine``, ``posture``, ``stiffness``,
            ``damping``, ``force_at``, ``observer_gain``, ``actuated``, ``control_period``.

    Returns:
        The run's summary; its ``files`` name what was written (``trajectory``: with an
        observer also its ``tau_ext[<joint>]`` columns, with pushes the torques they
        applied, ``tau_env[<joint>]``;
        ``plot``, ``recording`` (the target pose as a triad, pushes as arrows), ``poster``).
    """
    kind = "on the ground" if settings.get("ground") is not None else "of the hybrid controller"
    if out and (settings.get("ground") is not None or settings.get("controller") == "hybrid") and Path(out).suffix != ".csv":
        raise InputError("out", f"a .csv file for a run {kind} (its contact forces are columns)", repr(str(out)))
    trajectory, summary = run_named(robot, **settings)  # hybrid: robodyn.sim.hybrid_run
    # The controlled frame, else the frame asked for (it names the drawn path), else none.
    frame = summary.task.frame if summary.task is not None else settings.get("frame")
    task = np.asarray(summary.task.target) if summary.task is not None else None
    with outputs_together():  # every file of the run, or none of them
        if out:
            extras = {} if summary.observer is None else {"tau_ext": summary.observer.residual}
            if summary.pushes:
                extras["tau_env"] = applied_torques(robot, trajectory, push_wrenches(robot, summary.pushes)[1])
            run = summary.contact or summary.constrained  # a run with forces as columns writes them
            written = run.save(out, extras) if run else write_with_extras(Path(out), trajectory, extras)
            summary = summary.with_file("trajectory", str(written))
        if plot:
            from robodyn.viz.plots import plot_simulation  # matplotlib: only when a figure is asked for

            drawn = plot_simulation(robot, trajectory, plot, frame=frame, target=task, panels=summary.panels)
            summary = summary.with_file("plot", str(drawn))
        if record:
            from robodyn.viz.recording import record as write_recording  # meshcat: only for an animation

            rpy = None if summary.task is None or summary.task.target_rpy is None else summary.task.target_rpy
            _, forces = push_wrenches(robot, summary.pushes, frame)
            forces += summary.contact.force_arrows() if summary.contact else ()  # each contact frame's force
            written = write_recording(
                robot, trajectory, record, png=png, target=task, frame=frame,
                target_rotation=None if rpy is None else target_rotation(np.asarray(rpy)), forces=tuple(forces),
                drawings=summary.drawings,
            )  # fmt: skip
            summary = summary.with_file("recording", str(written))
            if png:
                summary = summary.with_file("poster", str(png))
    return summary


def run_observation(
    robot: Robot,
    path: PathLike,
    *,
    out: PathLike | None = None,
    plot: PathLike | None = None,
    **options: Any,
) -> ObservationRun:
    """:func:`robodyn.sim.observer.observe_file` plus its figure (``robodyn observe``).

    Args:
        robot: The model of the robot that moved.
        path: The trajectory file (with torques).
        out: CSV of the estimate (``t``, ``tau_ext[<joint>]``, with a frame its wrench).
        plot: PNG: the estimate against the applied external torques (the file's
            ``tau_env`` columns, when it has them).
        **options: ``gain``, ``frame``, ``threshold``, ``torque``.
    """
    with outputs_together():  # the estimate and its figure, or neither
        run = observe_file(robot, path, out=out, **options)
        if plot:
            from robodyn.viz.plots import plot_external_torques  # matplotlib: only when a figure is asked for

            plot_external_torques(run.t, run.residual, run.applied, run.dof_names, run.units, plot, gain=run.gain)
            run = replace(run, plot=str(plot))
    return run


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


@dataclass(frozen=True)
class RecordingRun:
    """A recording written: the HTML page and the stills and videos made of it.

    Attributes:
        path: The HTML file written (``None``: standard output).
        size: The page's size in [bytes].
        duration: Length of the animation in [s]; ``fps``: its frames per second.
        seconds: Wall-clock time the work took, in [s].
        extras: The still, filmstrip and video files written, in order.
        placeholders: Meshes drawn as placeholder boxes (why), empty when all were drawn.
    """

    path: str | None
    size: int
    duration: float
    fps: float
    seconds: float
    extras: tuple[str, ...] = ()
    placeholders: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys."""
        return {
            "path": self.path,
            "size_bytes": self.size,
            "duration_s": self.duration,
            "fps": self.fps,
            "seconds": self.seconds,
            "extras": list(self.extras),
            "placeholders": list(self.placeholders),
        }

    def headline(self) -> str:
        """``wrote <file> (<size> MB, <duration> s at <fps> fps, <time> s)``."""
        return (
            f"wrote {self.path or 'standard output'} ({self.size / 1e6:.2f} MB, {self.duration:.3g} s at {self.fps:g} fps, "
            f"{self.seconds:.2f} s)"
        )

    def text(self) -> str:
        """The headline, then one ``wrote`` line a still or video."""
        return "\n".join([self.headline(), *(f"wrote {extra}" for extra in self.extras)])


def record_files(
    robot: Robot,
    trajectory: Trajectory,
    out: PathLike,
    *,
    fps: float = 30.0,
    target: Any = None,
    frame: str | None = None,
    axes: tuple[str, ...] = (),
    max_mesh_bytes: int | None = None,
    png: PathLike | None = None,
    at: float = 0.0,
    filmstrip: int | None = None,
    videos: tuple[PathLike, ...] = (),
    video_fps: float = 15.0,
) -> RecordingRun:
    """Draw ``trajectory`` (:func:`robodyn.viz.recording.recording`) and write its files.

    The stills and videos are made before the HTML is written: a failed still leaves no half
    result.

    Args:
        robot, trajectory, fps, target, frame, axes: As for
            :func:`~robodyn.viz.recording.recording`.
        max_mesh_bytes: Largest mesh file drawn (``None``: the default of
            :mod:`robodyn.viz.mesh_files`).
        out: The HTML file (``-``: standard output).
        png: A still of the frame at ``at`` seconds, or with ``filmstrip`` that many frames
            side by side (needs Chromium).
        at: Time of the still in [s] from the motion's start.
        filmstrip: With ``png``: the number of frames of the filmstrip.
        videos: MP4 or GIF files of the motion (by extension), at ``video_fps``.
        video_fps: Frames per second of the videos.
    """
    from robodyn.viz.recording import recording  # meshcat (the viewer extra): only when recording

    started = time.perf_counter()
    cap: dict[str, Any] = {} if max_mesh_bytes is None else {"max_mesh_bytes": max_mesh_bytes}
    made = recording(robot, trajectory, fps=fps, target=target, frame=frame, axes=axes, **cap)
    if png:
        if filmstrip is not None:
            made.filmstrip(png, filmstrip)
        else:
            made.still(png, at=at)
    for path in videos:
        made.video(path, fps=video_fps)
    written = made.save(out)
    extras = ((str(png),) if png else ()) + tuple(str(path) for path in videos)
    return RecordingRun(
        None if written is None else str(written), len(made.html.encode()), made.duration, fps,
        time.perf_counter() - started, extras, tuple(made.placeholders),
    )  # fmt: skip
