"""The ``contact`` section of ``make bench``: solo12 standing at 1 kHz on its four feet,
robodyn's contact step against MuJoCo's on the same contacts and step (issue 41's Speed).

Both engines hold the neutral pose with the same PD written in Python (5 N m/rad, 0.1 N m
s/rad), called once a step; MuJoCo's feet are spheres of 0.1 mm on its plane, elliptic cones,
μ = 0.8, its contacts stiffened to their rigid limit (``solref`` two steps), as in
tests/sim/test_contact_mujoco.py. Each engine first settles 0.5 s (not timed), then runs
1 s of standing, the two alternated in every repeat; the figures are medians of the repeats
(CPU time of this thread, and wall time), the ratio the median of the repeats' ratios.
"""

from __future__ import annotations

import os
import statistics
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable

import numpy as np

import robodyn
from robodyn.sim.contact import ContactStepper, contact_kinematics, contact_step, generic_step
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.contact_solver import ContactSettings
from robodyn.sim.ground import ContactPoint, Ground

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
RADIUS, FRICTION, DT = 1e-4, 0.8, 1e-3


def _mujoco_solo(robot: robodyn.Robot):
    """solo12 in MuJoCo: the URDF's bodies on a free joint, four foot spheres, the plane."""
    import mujoco

    root = ET.fromstring(robot.urdf)
    for link in root.findall("link"):
        for element in [child for child in link if child.tag in ("visual", "collision")]:
            link.remove(element)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", fusestatic="false", discardvisual="true", balanceinertia="false")
    spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    spec.worldbody.first_body().add_freejoint()
    for foot in FEET:
        spec.body(foot).add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[RADIUS, 0, 0], condim=3, friction=[FRICTION, 0, 0])
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[50, 50, 0.1], condim=3, friction=[FRICTION, 0, 0])
    spec.option.timestep, spec.option.cone = DT, mujoco.mjtCone.mjCONE_ELLIPTIC
    model = spec.compile()
    model.geom_solref[:] = (2 * DT, 1.0)
    model.geom_solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    return mujoco, model


def _alternated(functions: list[Callable[[], object]], repeats: int) -> list[tuple[list[float], list[float]]]:
    """Per function, the CPU times (this thread's) and wall times of ``repeats`` alternated runs."""
    times: list[tuple[list[float], list[float]]] = [([], []) for _ in functions]
    for _ in range(repeats):
        for function, (cpu, wall) in zip(functions, times, strict=True):
            began_cpu, began_wall = time.thread_time(), time.perf_counter()
            function()
            cpu.append(time.thread_time() - began_cpu)
            wall.append(time.perf_counter() - began_wall)
    return times


def bench_contact(quick: bool) -> list[dict]:
    """solo12 standing on four feet at 1 kHz: a loop of robodyn's ``contact_step`` vs a loop
    of MuJoCo's ``mj_step``, the same Python controller in both; also ``simulate_contact``
    (the loop that records every sample), the numpy path (no C compiler), the general path
    (mimic robots') and a bare
    ``mj_step`` (no controller: solo12 then sags, its contacts still four)."""
    try:
        mujoco, model = _mujoco_solo(robot := robodyn.load("solo12"))
    except ImportError:
        return [{"case": "solo12 standing", "note": "MuJoCo not installed (pip install mujoco)"}]
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), RADIUS) for foot in FEET)
    ground, settings = Ground(friction=FRICTION), ContactSettings()
    q0 = robot.neutral_configuration()
    q0[2] -= contact_kinematics(robot, q0, ground, points)[0].min()
    target = q0[7:].copy()

    def hold(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        tau = np.zeros(robot.nv)
        tau[6:] = 5.0 * (target - q[7:]) - 0.1 * v[6:]
        return tau

    settled = simulate_contact(robot, ground=ground, contacts=points, controller=hold, duration=0.5, q0=q0)
    q1, v1 = settled.trajectory.q[-1], settled.trajectory.v[-1]
    data = mujoco.MjData(model)
    data.qpos[:] = np.concatenate([q0[:3], q0[6:7], q0[3:6], q0[7:]])  # quaternion w first
    steps = 1000
    for step in range(500):  # hold reads the joints alone: q[7:], v[6:] in either engine's layout
        data.qfrc_applied[:] = hold(step * DT, data.qpos, data.qvel)
        mujoco.mj_step(model, data)
    state = (data.qpos.copy(), data.qvel.copy())

    def loop(step_function: Callable) -> Callable[[], None]:
        def run() -> None:
            q, v, guess = q1, v1, None
            for step in range(steps):
                result = step_function(q, v, hold(step * DT, q, v), guess)
                q, v, guess = result.q, result.v, result.impulses

        return run

    ours = loop(lambda q, v, tau, guess: contact_step(robot, q, v, tau, DT, ground, points, settings=settings, guess=guess))
    general = loop(lambda q, v, tau, guess: generic_step(robot, q, v, tau, DT, ground, points, settings, guess))
    numpy_only = ContactStepper(robot, ground, points)
    numpy_only.kept = None  # as without a C compiler
    numpy_path = loop(lambda q, v, tau, guess: numpy_only.step(q, v, tau, DT, settings, guess))

    def ours_run() -> None:
        simulate_contact(robot, ground=ground, contacts=points, controller=hold, duration=(steps - 1) * DT, q0=q1, v0=v1)

    def theirs() -> None:
        data.qpos[:], data.qvel[:] = state
        for step in range(steps):
            data.qfrc_applied[:] = hold(step * DT, data.qpos, data.qvel)
            mujoco.mj_step(model, data)

    def theirs_bare() -> None:
        data.qpos[:], data.qvel[:] = state
        for _ in range(steps):
            mujoco.mj_step(model, data)

    repeats = 3 if quick else 7
    timed = _alternated([ours, theirs, ours_run, general, theirs_bare, numpy_path], repeats)
    (ours_cpu, ours_wall), (mj_cpu, mj_wall), (run_cpu, _), (general_cpu, _), (bare_cpu, _), (numpy_cpu, _) = timed
    duration = steps * DT
    run = simulate_contact(robot, ground=ground, contacts=points, controller=hold, duration=(steps - 1) * DT, q0=q1, v0=v1)
    theirs()  # MuJoCo's state after the same second, for the heights
    weight = robot.total_mass * 9.81
    return [
        {
            "case": "solo12 standing, 4 feet, 1 kHz, PD hold (Python, both)",
            "robodyn_step_us": statistics.median(ours_cpu) / steps * 1e6,
            "mujoco_step_us": statistics.median(mj_cpu) / steps * 1e6,
            "ratio_cpu": statistics.median(o / m for o, m in zip(ours_cpu, mj_cpu, strict=True)),
            "ratio_wall": statistics.median(o / m for o, m in zip(ours_wall, mj_wall, strict=True)),
            "robodyn_rtf": duration / statistics.median(ours_cpu),
            "mujoco_rtf": duration / statistics.median(mj_cpu),
            "simulate_contact_step_us": statistics.median(run_cpu) / steps * 1e6,
            "numpy_path_step_us": statistics.median(numpy_cpu) / steps * 1e6,
            "general_path_step_us": statistics.median(general_cpu) / steps * 1e6,
            "mujoco_bare_mj_step_us": statistics.median(bare_cpu) / steps * 1e6,
            "admm_steps": int((run.iterations > 0).sum()),
            "normal_sum_over_mg": float(run.normal_forces[-1].sum() / weight),
            "base_height_diff_m": float(abs(run.trajectory.q[-1, 2] - data.qpos[2])),
            "repeats": repeats,
            "load_average": os.getloadavg()[0],
            "note": f"CPU time of this thread, medians of alternated repeats; MuJoCo {mujoco.__version__}, elliptic cones, rigid-limit solref",
        }
    ]


__all__ = ["bench_contact"]
