"""Check robodyn's MJCF reader on the two public model collections, as shipped, against MuJoCo.

Run from the repository root: ``python scripts/corpus_check.py`` (``make corpus``). It needs
the network once: ``pip download --no-deps dm_control gymnasium`` into a cache folder
(``--dir``, default ``~/.cache/robodyn-corpus``), then reads the models from the wheels
(dm_control's ``suite/*.xml`` with their ``common/`` includes, Gymnasium's
``envs/mujoco/assets/*.xml``). Nothing is committed from them.

For every model MuJoCo loads, robodyn either

- loads it, and at a few random states (robodyn's ``q``, ``v``, ``a`` mapped to MuJoCo's by
  :meth:`robodyn.Robot.to_mujoco`, the file's gravity) its ``τ``, ``M`` and ``G`` are within
  1e-12 of MuJoCo's (``mj_inverse``, ``mj_fullM``, ``qfrc_bias`` at rest; constraints and
  passive forces (springs, dampers, fluid, gravity compensation) switched off in MuJoCo: they are not the rigid-body terms), relative to
  each quantity's largest entry; and every joint an actuator drives has the effort limit
  MuJoCo's compiled actuator ranges give (``gear`` × ``ctrlrange`` of a fixed-gain,
  bias-free actuator, within ``forcerange``, summed over the joint's actuators, within its
  ``actuatorfrcrange``: the larger magnitude), the others are not actuated; or
- refuses it with one sentence (a :class:`robodyn.exceptions.RobodynError`).

It prints a table (model, DoF, result, largest error, refusal reason or the number of
reported lines) and exits 1 on any mismatch or traceback.
"""

from __future__ import annotations

import argparse
import fnmatch
import math
import subprocess
import sys
import traceback
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The wheels (PyPI names) and, inside each, the folder of models and their file pattern.
COLLECTIONS = {
    "dm_control": ("dm_control/suite/", "dm_control/suite/*.xml"),
    "gymnasium": ("gymnasium/envs/mujoco/assets/", "gymnasium/envs/mujoco/assets/*.xml"),
}
#: The bar: each quantity within this of MuJoCo's, relative to its largest entry.
TOLERANCE = 1e-12
DEFAULT_DIR = Path.home() / ".cache" / "robodyn-corpus"


@dataclass
class Row:
    """One model's outcome."""

    model: str
    dof: str
    result: str  # "agree", "refused", "FAIL", "MuJoCo refuses"
    error: float
    note: str


def fetch(folder: Path) -> dict[str, Path]:
    """The two wheels in ``folder`` (downloaded when missing), by collection."""
    folder.mkdir(parents=True, exist_ok=True)
    wheels = {name: sorted(folder.glob(f"{name}-*.whl")) for name in COLLECTIONS}
    missing = [name for name, found in wheels.items() if not found]
    if missing:
        command = [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", *missing, "-d", str(folder)]
        subprocess.run(command, check=True)
        wheels = {name: sorted(folder.glob(f"{name}-*.whl")) for name in COLLECTIONS}
    return {name: found[-1] for name, found in wheels.items()}


def extract(wheel: Path, prefix: str, pattern: str, folder: Path) -> list[Path]:
    """The wheel's files under ``prefix`` unpacked into ``folder`` (once); the models matching
    ``pattern`` (their includes and assets unpacked beside them)."""
    target = folder / wheel.stem
    with zipfile.ZipFile(wheel) as archive:
        members = [name for name in archive.namelist() if name.startswith(prefix) and not name.endswith((".py", ".pyc", "/"))]
        for member in members:
            path = target / member
            if not path.exists():
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(archive.read(member))
    return sorted(target / member for member in members if fnmatch.fnmatch(member, pattern) and "/" not in member[len(prefix) :])


def mujoco_efforts(model) -> dict[str, float]:
    """The largest force magnitude MuJoCo's compiled actuators can apply at each joint they drive."""
    import mujoco

    ranges: dict[int, list[float]] = {}
    for index in range(model.nu):
        if int(model.actuator_trntype[index]) != int(mujoco.mjtTrn.mjTRN_JOINT):
            continue
        low, high = -math.inf, math.inf
        fixed = int(model.actuator_gaintype[index]) == int(mujoco.mjtGain.mjGAIN_FIXED)
        unbiased = int(model.actuator_biastype[index]) == int(mujoco.mjtBias.mjBIAS_NONE)
        dynamics = int(model.actuator_dyntype[index])
        filtered = (int(mujoco.mjtDyn.mjDYN_FILTER), int(mujoco.mjtDyn.mjDYN_FILTEREXACT))
        passes = dynamics == int(mujoco.mjtDyn.mjDYN_NONE) or dynamics in filtered
        if fixed and unbiased and passes and model.actuator_ctrllimited[index]:
            gain = float(model.actuator_gainprm[index, 0])
            low, high = sorted(gain * float(value) for value in model.actuator_ctrlrange[index])
            if dynamics in filtered:
                low, high = min(low, 0.0), max(high, 0.0)
        if model.actuator_forcelimited[index]:
            low, high = (
                max(low, float(model.actuator_forcerange[index, 0])),
                min(high, float(model.actuator_forcerange[index, 1])),
            )
        gear = float(model.actuator_gear[index, 0])
        low, high = sorted((gear * low, gear * high)) if gear else (0.0, 0.0)
        joint = int(model.actuator_trnid[index, 0])
        total = ranges.setdefault(joint, [0.0, 0.0])
        total[0] += low
        total[1] += high
    efforts = {}
    for joint, (low, high) in ranges.items():
        if model.jnt_actfrclimited[joint]:
            low, high = max(low, float(model.jnt_actfrcrange[joint, 0])), min(high, float(model.jnt_actfrcrange[joint, 1]))
        efforts[mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)] = max(abs(low), abs(high))
    return efforts


def velocity_map(robot, q: np.ndarray) -> np.ndarray:
    """``T`` with MuJoCo's ``qvel = T v`` at ``q`` (linear in ``v``: by :meth:`to_mujoco` of unit vectors)."""
    return np.array([robot.to_mujoco(q, unit)[1] for unit in np.eye(robot.nv)]).T


def compare(robot, model, states: int, seed: int) -> float:
    """The largest relative difference of τ, M and G from MuJoCo's over random states."""
    import mujoco

    bits = mujoco.mjtDisableBit
    model.opt.disableflags |= bits.mjDSBL_CONSTRAINT | bits.mjDSBL_SPRING | bits.mjDSBL_DAMPER
    model.opt.density, model.opt.viscosity, model.opt.wind[:] = 0.0, 0.0, 0.0  # fluid forces: reported, not modelled
    model.body_gravcomp[:] = 0.0  # gravity compensation: reported, not modelled
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    worst = 0.0
    for q in np.atleast_2d(robot.random_configuration(rng, states)):
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        transform = velocity_map(robot, q)
        data.qpos[:], data.qvel[:] = robot.to_mujoco(q, v)
        data.qacc[:] = transform @ a
        if robot.floating_base:  # MuJoCo's linear acceleration is the world frame's: + R (ω × v)
            data.qacc[:3] += transform[:3, :3] @ np.cross(v[3:6], v[:3])
        mujoco.mj_inverse(model, data)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, full, data.qM) if hasattr(data, "qM") else mujoco.mj_fullM(model, data, full)
        theirs = {"tau": transform.T @ data.qfrc_inverse, "M": transform.T @ full @ transform}
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        theirs["G"] = transform.T @ data.qfrc_bias
        ours = {"tau": robot.inverse_dynamics(q, v, a), "M": robot.mass_matrix(q), "G": robot.gravity(q)}
        for name, value in theirs.items():
            scale = max(float(np.abs(value).max(initial=0.0)), 1e-300)
            worst = max(worst, float(np.abs(ours[name] - value).max(initial=0.0)) / scale)
    return worst


def kinematics_mismatch(robot, model, states: int, seed: int) -> tuple[float, str | None]:
    """The largest difference of the sites' world poses from MuJoCo's (``mj_kinematics``) over
    random states, relative to the model's size, and a mismatch of the state conversion
    (``from_mujoco`` of ``to_mujoco``), of a joint's damping or Coulomb friction
    (``frictionloss``), or of its range (robodyn's plus ``ref``), if any."""
    import mujoco
    import pinocchio as pin

    data = mujoco.MjData(model)
    frames, known = {}, robot.frame_ids
    for index in range(model.nsite):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, index)
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.site_bodyid[index]))
        frames[index] = f"site:{name}" if f"site:{name}" in known else name
        if frames[index] not in known:
            if name is None or body is None or (model.site_bodyid[index] == 0 and robot.floating_base):
                del frames[index]  # a floating robot's world sites (reported), or a site without a name
                continue
            return 0.0, f"site {name!r} is no frame of the robot"
    pinocchio_data = robot.model.createData()
    rng = np.random.default_rng(seed)
    worst = 0.0
    for q in np.atleast_2d(robot.random_configuration(rng, states)):
        v = rng.normal(size=robot.nv)
        back = robot.from_mujoco(*robot.to_mujoco(q, v))
        if not (np.allclose(back[0], q, rtol=0, atol=1e-12) and np.allclose(back[1], v, rtol=0, atol=1e-12)):
            return worst, "from_mujoco(to_mujoco(q, v)) is not (q, v)"
        data.qpos[:] = robot.to_mujoco(q)[0]
        mujoco.mj_kinematics(model, data)
        pin.framesForwardKinematics(robot.model, pinocchio_data, q)
        size = max(1.0, float(np.abs(data.xpos).max()))
        for index, frame in frames.items():
            placement = pinocchio_data.oMf[known[frame]]
            worst = max(
                worst,
                float(np.abs(placement.translation - data.site_xpos[index]).max()) / size,
                float(np.abs(placement.rotation - data.site_xmat[index].reshape(3, 3)).max()),
            )
    for dof in robot.dofs:
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, dof.joint)
        if dof.is_base or index < 0:
            continue
        address = int(model.jnt_dofadr[index])
        for what, mine, theirs in (
            ("damping", dof.damping, model.dof_damping[address]),
            ("friction", dof.friction, model.dof_frictionloss[address]),
        ):
            if not math.isclose(mine, float(theirs), rel_tol=1e-12, abs_tol=1e-15):
                return worst, f"joint {dof.joint!r}: {what} {mine:g}, MuJoCo's {float(theirs):g}"
        if not model.jnt_limited[index]:
            continue
        offset = dict(robot.source.joint_offsets).get(dof.joint, 0.0)
        mine, theirs = np.array([dof.lower, dof.upper]) + offset, model.jnt_range[index]
        if not np.allclose(mine, theirs, rtol=1e-12, atol=1e-12):
            return worst, f"joint {dof.joint!r}: range {mine.tolist()}, MuJoCo's {theirs.tolist()}"
    return worst, None


def effort_mismatch(robot, model) -> str | None:
    """Which joint's effort limit or actuated flag differs from MuJoCo's actuators, if one does."""
    expected = mujoco_efforts(model)
    if model.nu == 0:
        return None
    for dof in robot.dofs:
        if dof.is_base:
            continue
        if dof.joint in expected:
            want = expected[dof.joint]
            if not (dof.effort_limit == want or math.isclose(dof.effort_limit, want, rel_tol=1e-12)):
                return f"joint {dof.joint!r}: effort limit {dof.effort_limit:g}, MuJoCo's actuators {want:g}"
            if not dof.actuated:
                return f"joint {dof.joint!r}: driven by an actuator but not actuated"
        elif dof.actuated and all(model.actuator_trntype[i] == 0 for i in range(model.nu)):
            return f"joint {dof.joint!r}: actuated, but no actuator drives it"
    return None


def check(path: Path, label: str, states: int, seed: int) -> Row:
    """One model's row."""
    import mujoco

    import robodyn
    from robodyn.exceptions import RobodynError

    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as refusal:  # MuJoCo's own refusal: not counted
        return Row(label, "-", "MuJoCo refuses", math.nan, str(refusal).splitlines()[0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            robot = robodyn.load(path)
        except RobodynError as refused:
            message = str(refused).replace(f"{path}: ", "")
            result = "refused" if "\n" not in message else "FAIL"
            return Row(label, str(model.nv), result, math.nan, message if result == "refused" else "a multi-line refusal")
        except Exception:  # a traceback is a bug: reported as a failure
            return Row(label, str(model.nv), "FAIL", math.nan, traceback.format_exc().strip().splitlines()[-1])
    reported = sum(1 for warning in caught if issubclass(warning.category, robodyn.RobodynWarning))
    if robot.nv != model.nv:
        return Row(label, f"{robot.nv} vs {model.nv}", "FAIL", math.nan, "a different number of degrees of freedom")
    try:
        error = compare(robot, model, states, seed)
        placement, mismatch = kinematics_mismatch(robot, model, states, seed)
        error = max(error, placement)
        mismatch = mismatch or effort_mismatch(robot, model)
    except Exception:  # a traceback: a failure
        return Row(label, str(robot.nv), "FAIL", math.nan, traceback.format_exc().strip().splitlines()[-1])
    if mismatch is not None:
        return Row(label, str(robot.nv), "FAIL", error, mismatch)
    result = "agree" if error <= TOLERANCE else "FAIL"
    return Row(label, str(robot.nv), result, error, f"{reported} reported line(s)")


def main(argv: list[str] | None = None) -> int:
    """Print the table; exit status 1 on any mismatch or traceback."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, default=DEFAULT_DIR, help=f"cache folder for the wheels (default {DEFAULT_DIR})")
    parser.add_argument("--states", type=int, default=3, help="random states per model (default 3)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--only", help="comma-separated model labels (e.g. dm_control/reacher)")
    arguments = parser.parse_args(argv)
    rows = []
    for collection, wheel in fetch(arguments.dir).items():
        prefix, pattern = COLLECTIONS[collection]
        for path in extract(wheel, prefix, pattern, arguments.dir):
            label = f"{collection}/{path.stem}"
            if arguments.only and label not in arguments.only.split(","):
                continue
            rows.append(check(path, label, arguments.states, arguments.seed))
            row = rows[-1]
            print(f"{row.model:42} {row.dof:>5} {row.result:15} {row.error:9.2e}  {row.note}", flush=True)
    counts = {key: sum(row.result == key for row in rows) for key in ("agree", "refused", "FAIL", "MuJoCo refuses")}
    errors = [row.error for row in rows if row.result == "agree"]
    print(
        f"{len(rows)} models: {counts['agree']} load and agree, {counts['refused']} refused with a reason, "
        f"{counts['FAIL']} failing, {counts['MuJoCo refuses']} refused by MuJoCo; "
        f"worst error of those that agree {max(errors, default=0.0):.2e}"
    )
    return 1 if counts["FAIL"] else 0


if __name__ == "__main__":
    sys.exit(main())
