"""`robodyn simulate --keyframe NAME`: a run starts at an MJCF file's keyframe (MuJoCo's own
``key_qpos``), never together with --q0, and an unknown name is refused listing the file's."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main

# a free body with one hinged arm; the keyframe turns, lifts and bends it away from qpos0
ARM = """<mujoco model="keyed"><option gravity="0.2 -0.1 -9.7"/><worldbody>
<body name="torso" pos="0 0 0.4"><freejoint name="root"/><geom type="box" size="0.1 0.08 0.05" mass="2"/>
<body name="arm" pos="0.1 0 0"><joint name="elbow" type="hinge" axis="0 1 0" range="-2 2"/>
<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02" mass="0.3"/></body></body></worldbody>
<keyframe><key name="home" qpos="0.3 -0.2 0.9 0.8 0.1 0.4 0.3 0.7"/><key name="flat" qpos="0 0 0.2 1 0 0 0 0"/></keyframe>
</mujoco>"""


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture
def arm(tmp_path):
    path = tmp_path / "keyed.xml"
    path.write_text(ARM)
    return path


def test_simulate_starts_at_the_keyframe_mujoco_reads(capsys, tmp_path, arm):
    out = tmp_path / "x.csv"
    status, _, _ = run(capsys, "simulate", str(arm), "--keyframe", "home", "--duration", "0.01", "--out", str(out))
    assert status == 0
    mujoco = pytest.importorskip("mujoco")  # MuJoCo's own reading of the keyframe (the bench extra)
    model = mujoco.MjModel.from_xml_path(str(arm))
    home = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    with pytest.warns(robodyn.RobodynWarning):  # the file's keyframes, said at load
        robot = robodyn.load(arm)
    expected = robot.from_mujoco(model.key_qpos[home])[0]
    assert np.abs(expected - robot.default_configuration()).max() > 0.3  # not the default start
    q = robodyn.Trajectory.load(out).q[0]
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-12)


def test_keyframe_and_q0_together_are_refused_in_one_line(capsys, arm):
    status, _, err = run(capsys, "simulate", str(arm), "--keyframe", "home", "--q0", "0,0,0.4,0,0,0,1,0", "--duration", "0.01")
    errors = [line for line in err.splitlines() if line.startswith("robodyn: error:")]  # after the load's keyframe line
    assert status == 2 and errors == ["robodyn: error: --keyframe must be left out with --q0 (each sets the start), got both."]


def test_an_unknown_keyframe_is_refused_listing_the_files_keyframes(capsys, arm):
    status, _, err = run(capsys, "simulate", str(arm), "--keyframe", "stand", "--duration", "0.01")
    errors = [line for line in err.splitlines() if line.startswith("robodyn: error:")]
    assert status == 2 and errors == [
        "robodyn: error: --keyframe must be one of the file's MJCF keyframes ('home', 'flat'), got 'stand'."
    ]
