"""Gymnasium's ant and half_cheetah dropped on their own floor: robodyn against MuJoCo.

Run ``python scripts/gymnasium_ground.py [--cache DIR]``. The MJCF files are Gymnasium's as
shipped (``gymnasium/envs/mujoco/assets``), taken from its wheel on PyPI
(``pip download --no-deps gymnasium==1.4.0``) into a cache directory, never committed;
offline and without a cached copy the script says so and stops.

Both engines run 2 s of a passive drop at 1 ms from the same start, with the file's
contacts, friction and joint limits (robodyn: ``limits="enforce"``, the limits as rows of
the contact problem). MuJoCo is brought to the model robodyn simulates: contacts and joint
limits stiffened to their rigid limit (``solref`` two steps, critically damped; ``solimp``
0.99–0.9999), elliptic cones, no contact margin (the ant's 0.01 m, which robodyn does not
read), no joint springs (half_cheetah's ``stiffness``, which robodyn leaves out and says so),
Euler integration at 1 ms. The starts: the ant at robodyn's default (its joints clipped into
their ranges: the ankles on their stops), its lowest contact point 5 cm above the floor; the
half_cheetah at the file's ``qpos0``. Compared: the rest pose (height, attitude, joints), the
links in contact at the end and the sum of normal forces (the last sample and the mean of the
last 0.1 s) against ``m g``.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np

import robodyn
from robodyn.sim.contact_checks import start_above
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import resolve_ground

VERSION = "1.4.0"
ASSETS = "gymnasium/envs/mujoco/assets"
DT, DURATION = 1e-3, 2.0
DEFAULT_CACHE = Path.home() / ".cache" / "robodyn" / "gymnasium"


def assets(cache: Path = DEFAULT_CACHE) -> Path | None:
    """The directory of Gymnasium's MJCF files (downloaded once into ``cache``), or ``None``
    when the wheel cannot be had (offline)."""
    folder = cache / VERSION / ASSETS
    if (folder / "ant.xml").is_file() and (folder / "half_cheetah.xml").is_file():
        return folder
    cache.mkdir(parents=True, exist_ok=True)
    command = [sys.executable, "-m", "pip", "download", "--no-deps", f"gymnasium=={VERSION}", "-d", str(cache), "-q"]
    try:
        subprocess.run(command, check=True, capture_output=True, timeout=120)
    except (OSError, subprocess.SubprocessError):
        return None
    wheels = sorted(cache.glob(f"gymnasium-{VERSION}-*.whl"))
    if not wheels:
        return None
    with zipfile.ZipFile(wheels[0]) as wheel:
        for name in wheel.namelist():
            if name.startswith(ASSETS) and name.endswith(".xml"):
                wheel.extract(name, cache / VERSION)
    return folder


def stiffened(mujoco, path: Path):
    """MuJoCo's model of ``path`` brought to robodyn's (module docstring)."""
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep, model.opt.cone, model.opt.integrator = (
        DT,
        mujoco.mjtCone.mjCONE_ELLIPTIC,
        mujoco.mjtIntegrator.mjINT_EULER,
    )
    for solref, solimp in ((model.geom_solref, model.geom_solimp), (model.jnt_solref, model.jnt_solimp)):
        solref[:] = (2 * DT, 1.0)
        solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    model.geom_margin[:] = 0.0
    model.jnt_stiffness[:] = 0.0
    return model


def _robodyn_q(robot: robodyn.Robot, model, qpos: np.ndarray) -> np.ndarray:
    """MuJoCo's ``qpos`` as robodyn's ``q`` (a free joint's quaternion x y z w; joints by name)."""
    address = {model.joint(i).name: int(model.jnt_qposadr[i]) for i in range(model.njnt)}
    joints = robot.joint_names[1:] if robot.floating_base else robot.joint_names
    values = [qpos[address[name]] for name in joints]
    return np.concatenate([qpos[:3], qpos[4:7], qpos[3:4], values]) if robot.floating_base else np.array(values)


def _mujoco_qpos(robot: robodyn.Robot, model, q: np.ndarray) -> np.ndarray:
    qpos = model.qpos0.copy()
    joints = robot.joint_names[1:] if robot.floating_base else robot.joint_names
    if robot.floating_base:
        qpos[:7] = np.concatenate([q[:3], q[6:7], q[3:6]])
    for name, value in zip(joints, q[7:] if robot.floating_base else q, strict=True):
        qpos[model.jnt_qposadr[model.joint(name).id]] = value
    return qpos


def _mujoco_body(robot: robodyn.Robot, q: np.ndarray, link: str, data) -> int:
    """The MuJoCo body whose origin is nearest robodyn's ``link`` (the MJCF reader keeps the
    bodies' frames; unnamed bodies get other names in the two)."""
    return int(np.argmin(np.linalg.norm(data.xpos - robot.frame_position(q, link), axis=1)))


def compare(path: Path, limits: str = "enforce") -> dict[str, float | str]:
    """Drop the robot of ``path`` in both engines (module docstring); the figures compared
    (``limits="warn"``: robodyn's joints move through their limits, a negative control)."""
    import mujoco

    model, robot = stiffened(mujoco, path), robodyn.load(path)
    ground = resolve_ground(robot, "file")
    assert ground is not None  # both files have a floor
    q0 = _robodyn_q(robot, model, model.qpos0)
    if robot.floating_base:
        q0 = start_above(robot, robot.default_configuration(), ground, "collision")[0]
    data = mujoco.MjData(model)
    data.qpos[:] = _mujoco_qpos(robot, model, q0)
    totals = []
    for _ in range(round(DURATION / DT)):
        mujoco.mj_step(model, data)
        force, total = np.zeros(6), 0.0
        for index in range(data.ncon):
            mujoco.mj_contactForce(model, data, index, force)
            total += force[0]
        totals.append(total)
    run = simulate_contact(robot, ground=ground, duration=DURATION, dt=DT, q0=q0, limits=limits)
    ours, theirs = run.trajectory.q[-1], _robodyn_q(robot, model, data.qpos)
    their_links = sorted({int(model.geom_bodyid[data.contact[i].geom[1]]) for i in range(data.ncon)})
    our_links = sorted({run.frames[i] for i in np.flatnonzero(run.active[-1])})
    ours_in_mujoco = sorted(_mujoco_body(robot, ours, link, data) for link in our_links)  # unnamed bodies: by place
    weight = robot.total_mass * float(np.linalg.norm(robot.model.gravity.linear))
    normal = run.normal_forces.sum(axis=1)
    window = round(0.1 / DT)
    base = 3 if robot.floating_base else 2  # the height: z, or the planar cheetah's rootz
    lower, upper = robot.physical_limits()
    joints = run.trajectory.q[:, robot.nq - len(lower) :]
    attitude = 2 * math.acos(min(abs(float(ours[3:7] @ theirs[3:7])), 1.0)) if robot.floating_base else abs(ours[2] - theirs[2])
    return {
        "robot": robot.name,
        "height (robodyn, MuJoCo) [m]": f"{ours[base - 1]:.5f}, {theirs[base - 1]:.5f}",
        "height apart [m]": abs(ours[base - 1] - theirs[base - 1]),
        "attitude apart [rad]": attitude,
        "joints apart [rad]": float(np.abs(ours[robot.nq - len(lower) :] - theirs[robot.nq - len(lower) :]).max()),
        "links in contact": ", ".join(our_links)
        + ("  (the same in MuJoCo)" if ours_in_mujoco == their_links else "  (not MuJoCo's)"),
        "same contact set": float(ours_in_mujoco == their_links),
        "Σ normal / m g − 1, last (robodyn, MuJoCo)": f"{normal[-1] / weight - 1:.2e}, {totals[-1] / weight - 1:.2e}",
        "Σ normal / m g − 1, mean of 0.1 s (robodyn, MuJoCo)": f"{normal[-window:].mean() / weight - 1:.2e}, {np.mean(totals[-window:]) / weight - 1:.2e}",
        "mean normal error": abs(normal[-window:].mean() / weight - 1),
        "deepest past a limit [rad]": float(np.maximum(lower - joints, joints - upper).max()),
        "steps ADMM stopped short": float((~run.converged).sum()),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="where the wheel and its MJCF files are kept")
    folder = assets(parser.parse_args().cache)
    if folder is None:
        print(f"gymnasium {VERSION}'s wheel is not available (offline?): nothing compared")
        return 1
    for name in ("ant", "half_cheetah"):
        for key, value in compare(folder / f"{name}.xml").items():
            print(f"{key}: {value:.3g}" if isinstance(value, float) else f"{key}: {value}")
        print()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
