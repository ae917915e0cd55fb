"""scripts/corpus_check.py (``make corpus``) on files written for the tests: a model that
agrees passes, and each of its checks fails when robodyn's number is wrong (negative controls).
The public collections themselves are not downloaded here (that needs the network)."""

from __future__ import annotations

import importlib.util
import sys

import pytest

import robodyn
from tests.conftest import ROOT

mujoco = pytest.importorskip("mujoco")
pytestmark = pytest.mark.filterwarnings("ignore::robodyn.exceptions.RobodynWarning")  # the arm's asymmetric ranges

#: Two motors on the shoulder (gear 2 × ctrl [−3, 3] within force [−4, 5]: [−6, 6]; gear 1 ×
#: ctrl [−1, 2]: [−1, 2]; summed [−7, 8]) within its actuatorfrcrange [−7.5, 7.5]: 7.5 N m.
#: The elbow: a filtered general actuator of gain 4 and ctrl [0.5, 1] ([0, 4], the activation
#: starts at 0), gear 3: 12 N m. The wrist is passive. A ref, a site by fromto, a world site.
ARM = """<mujoco><compiler angle="radian" autolimits="true"/><option gravity="0.4 -0.3 -9.6"/><worldbody>
<site name="goal" pos="0.3 0 0.2"/>
<body name="upper" pos="0 0 0.5"><joint name="shoulder" axis="0 1 0" ref="0.3" actuatorfrcrange="-7.5 7.5" range="-1 1"/>
  <geom type="capsule" fromto="0 0 0 0.4 0 0.05" size="0.04"/>
  <site name="ray" type="capsule" size="0.005" fromto="0.41 -0.02 0.11 0.34 0 0.115"/>
  <body name="lower" pos="0.4 0 0"><joint name="elbow" axis="0.2 1 0.1" damping="0.3" frictionloss="0.05"/>
    <geom type="box" size="0.15 0.03 0.02" pos="0.15 0 0" mass="0.7"/>
    <body name="hand" pos="0.3 0 0"><joint name="wrist" type="slide" axis="1 0 0" range="-0.1 0.1"/>
      <geom type="sphere" size="0.05" mass="0.3"/></body>
  </body>
</body></worldbody>
<actuator>
  <motor joint="shoulder" gear="2" ctrlrange="-3 3" forcerange="-4 5"/>
  <motor joint="shoulder" ctrlrange="-1 2"/>
  <general joint="elbow" gear="3" gainprm="4" dyntype="filter" dynprm="0.1" ctrlrange="0.5 1"/>
</actuator></mujoco>"""


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("corpus_check", ROOT / "scripts" / "corpus_check.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["corpus_check"] = module  # its dataclass looks its module up
    spec.loader.exec_module(module)
    yield module
    del sys.modules["corpus_check"]


@pytest.fixture
def arm(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    return path


def test_a_model_robodyn_reads_as_mujoco_does_agrees(script, arm):
    row = script.check(arm, "arm", 3, 0)
    assert row.result == "agree" and row.error < script.TOLERANCE, row
    assert script.mujoco_efforts(mujoco.MjModel.from_xml_path(str(arm))) == {"shoulder": 7.5, "elbow": 12.0}
    robot = robodyn.load(arm)
    assert {dof.name: dof.effort_limit for dof in robot.dofs if dof.actuated} == {"shoulder": 7.5, "elbow": 12.0}


def test_a_wrong_gravity_a_wrong_effort_limit_and_a_misplaced_site_each_fail(script, arm, monkeypatch, tmp_path):
    load = robodyn.load
    monkeypatch.setattr(robodyn, "load", lambda path: load(path, gravity=(0.4, -0.3, -9.7)))
    assert script.check(arm, "arm", 3, 0).result == "FAIL"
    monkeypatch.setattr(robodyn, "load", load)
    other = tmp_path / "other.xml"
    other.write_text(ARM.replace('actuatorfrcrange="-7.5 7.5"', 'actuatorfrcrange="-6 6"'))
    said = script.effort_mismatch(robodyn.load(arm), mujoco.MjModel.from_xml_path(str(other)))
    assert said == "joint 'shoulder': effort limit 7.5, MuJoCo's actuators 6"
    moved = tmp_path / "moved.xml"
    moved.write_text(ARM.replace('fromto="0.41 -0.02 0.11 0.34 0 0.115"', 'fromto="0.34 0 0.115 0.41 -0.02 0.11"'))
    error, _ = script.kinematics_mismatch(robodyn.load(arm), mujoco.MjModel.from_xml_path(str(moved)), 2, 0)
    assert error > 0.1  # the site turned end over end


def test_a_model_robodyn_refuses_is_a_one_line_refusal_and_a_model_mujoco_refuses_is_not_counted(script, tmp_path):
    ball = tmp_path / "ball.xml"
    ball.write_text(ARM.replace('<joint name="elbow" axis="0.2 1 0.1"', '<joint name="elbow" type="ball"').replace(
        '<general joint="elbow" gear="3" gainprm="4" dyntype="filter" dynprm="0.1" ctrlrange="0.5 1"/>', ""
    ))  # fmt: skip
    row = script.check(ball, "ball", 3, 0)
    assert row.result == "refused" and "ball joints" in row.note and "\n" not in row.note
    broken = tmp_path / "broken.xml"
    broken.write_text(ARM.replace('joint="elbow" gear="3"', 'joint="knee" gear="3"'))
    assert script.check(broken, "broken", 3, 0).result == "MuJoCo refuses"
