"""Issue 39, ``run_hybrid``'s refusals: each is one whole sentence naming the parameter,
what it must be and the offending value (a gain given as text or as ragged lists included:
they were numpy's own ``ValueError``, and ``-1`` was said ``array(-1.)``)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError, StaticFrameError
from robodyn.sim.hybrid_run import run_hybrid, run_named
from robodyn.urdf.models.rp_arm import rp_arm_urdf

WALL = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0))  # the RP arm's tip starts at x = 0.9
RUN = {"force": 1.0, "surface": WALL, "duration": 0.02, "dt": 0.01}
CONFIGURATION = "must be one configuration of 2 finite values, got"
AMPLITUDES = "along must be 3 amplitudes in [m] (or 2 x 3: the sine's and the cosine's), got"


@pytest.mark.parametrize(
    ("change", "sentence"),
    [
        ({"force": None}, "force must be given for the hybrid controller, got nothing."),
        ({"surface": None}, "surface must be given for the hybrid controller, got nothing."),
        ({"force": -1.0}, "force must be a finite normal force >= 0 in [N] (pressing), got -1.0."),
        (
            {"surface": (1.0, 0.0, 0.0)},
            "surface must be a point X,Y,Z in [m] and an outward normal NX,NY,NZ, got (1.0, 0.0, 0.0).",
        ),
        ({"surface": 7}, "surface must be a point X,Y,Z in [m] and an outward normal NX,NY,NZ, got 7."),
        (  # the gap: -1 * (0.9 - 1e300)
            {"surface": ((1e300, 0.0, 0.0), (-1.0, 0.0, 0.0))},
            "surface must be a plane end_effector can reach from the default configuration, got 1e+300 m away.",
        ),
        (  # x = 5: the prismatic joint2 would reach 5 - 0.9 m, its limit is 0.3 m (urdf/rp_arm.urdf)
            {"surface": ((5.0, 0.0, 0.0), (-1.0, 0.0, 0.0))},
            "q0 must be given: the default configuration projected onto the surface breaks a joint limit, "
            "got joint2 position 4.1 m beyond 0.3 m from t = 0 s.",
        ),
        ({"q0": "ab"}, f"q0 {CONFIGURATION} 'ab'."),
        ({"q0": [0.0]}, f"q0 {CONFIGURATION} shape (1,)."),
        ({"q0": [0.0, np.nan]}, f"q0 {CONFIGURATION} non-finite values."),
        ({"posture": [0.0]}, f"posture {CONFIGURATION} shape (1,)."),
        ({"posture": [np.inf, 0.0]}, f"posture {CONFIGURATION} non-finite values."),
        ({"posture": ["x", 1]}, f"posture {CONFIGURATION} ['x', 1]."),
        ({"kp": [1.0, 2.0]}, "kp must be one finite gain >= 0 for the hybrid controller, got 2 values."),
        ({"kd": [[1.0], [2.0], [3.0]]}, "kd must be one finite gain >= 0 for the hybrid controller, got 3 values."),
        ({"kp": "x"}, "kp must be one finite gain >= 0 for the hybrid controller, got 'x'."),
        ({"kd": [[1], [1, 2]]}, "kd must be one finite gain >= 0 for the hybrid controller, got [[1], [1, 2]]."),
        ({"kp": -1.0}, "kp must be one finite gain >= 0, got -1.0."),
        ({"kd": [np.nan]}, "kd must be one finite gain >= 0, got nan."),
        ({"target": (0.9, 0.0, 0.0)}, "target must be a point on the surface (within 0.0001 m), got 0.1 m off it."),
        (
            {"along": (0.1, 0.0, 0.0)},
            "along must be amplitudes DX,DY,DZ[:EX,EY,EZ] in [m] along the surface (normal part 0), got normal part 0.1 m.",
        ),
        ({"along": (0.0, 0.0)}, f"{AMPLITUDES} (0.0, 0.0)."),
        ({"along": "x"}, f"{AMPLITUDES} 'x'."),
        ({"along": [(0, 0, 0.1), (0, 0, np.inf)]}, f"{AMPLITUDES} [(0, 0, 0.1), (0, 0, inf)]."),
        ({"frequency": -1.0}, "frequency must be a finite frequency >= 0 in [Hz], got -1.0."),
        ({"surface": ((1.0, 0.0), (-1.0, 0.0, 0.0))}, "surface must be 3 finite numbers in [m], got shape (2,)."),
        ({"target": (1.0, 0.0)}, "target must be 3 finite numbers in [m], got shape (2,)."),
        (  # 1.5e-9 m out of 0.1 m: beyond 1e-9 m (the tolerance is relative only above 1 m)
            {"along": (1.5e-9, 0.0, 0.1)},
            "along must be amplitudes DX,DY,DZ[:EX,EY,EZ] in [m] along the surface (normal part 0), got normal part 1.5e-09 m.",
        ),
        # a long value is said by its first 80 characters
        ({"surface": "s" * 100}, "surface must be a point X,Y,Z in [m] and an outward normal NX,NY,NZ, got '" + "s" * 79 + "."),
        ({"q0": "q" * 100}, f"q0 {CONFIGURATION} '" + "q" * 79 + "."),
        ({"kp": "k" * 100}, "kp must be one finite gain >= 0 for the hybrid controller, got '" + "k" * 79 + "."),
        ({"along": "a" * 100}, f"{AMPLITUDES} '" + "a" * 79 + "."),
    ],
)
def test_a_refusal_is_one_sentence_naming_the_parameter_and_its_value(change, sentence):
    with pytest.raises(InputError) as caught:
        run_hybrid(robodyn.load("rp_arm"), **(RUN | change))
    assert str(caught.value) == sentence


def test_a_given_start_off_the_surface_is_refused_with_its_gap():
    off = np.array([0.0, 0.05])  # the tip at x = 0.95: 0.05 m before the wall
    with pytest.raises(InputError) as caught:
        run_hybrid(robodyn.load("rp_arm"), **RUN, q0=off)
    assert (
        str(caught.value) == "q0 must be a configuration with end_effector on the surface (within 0.0001 m), got 0.05 m off it."
    )


def test_a_floating_robot_is_refused_naming_it():
    with pytest.raises(InputError) as caught:
        run_hybrid(robodyn.load(rp_arm_urdf(), floating_base=True), **RUN)
    assert str(caught.value) == (
        "controller must be a fixed-base robot for the hybrid controller (a floating base has no actuator), got 'rp_arm'."
    )


@pytest.mark.parametrize(
    ("name", "value"), [("force", 1.0), ("surface", WALL), ("along", (0, 0, 1)), ("frequency", 2.0), ("force", "f" * 100)]
)
def test_a_hybrid_option_with_another_controller_is_one_sentence_with_its_value(name, value):
    with pytest.raises(InputError) as caught:
        run_named(robodyn.load("rp_arm"), controller="passive", duration=0.02, **{name: value})
    assert str(caught.value) == f"{name} must be given only with the hybrid controller, got {repr(value)[:80]}."


def test_unset_hybrid_options_reach_the_other_controller():  # negative control: None is not refused
    trajectory, summary = run_named(
        robodyn.load("rp_arm"), controller="passive", duration=0.02, dt=0.01, force=None, surface=None, along=None
    )
    assert summary.controller == "passive" and len(trajectory) == 3


def test_amplitudes_within_the_tolerance_are_taken():  # the negative controls of the normal part's tolerance
    robot = robodyn.load("rp_arm")
    run_hybrid(robot, **RUN, along=(5e-9, 0.0, 10.0), limits="ignore")  # 5e-10 of 10 m: within 1e-9 relative
    run_hybrid(robot, **RUN, along=(0.5e-9, 0.0, 0.1))  # within 1e-9 m
    _, summary = run_hybrid(robot, **RUN, along=("0", "0", "0.1"))  # numbers as text, as numpy reads them
    _, floats = run_hybrid(robot, **RUN, along=(0.0, 0.0, 0.1))
    assert summary.forces.motion_error == floats.forces.motion_error


def test_a_frame_no_joint_moves_is_refused_saying_what_it_was_for():
    with pytest.raises(StaticFrameError) as caught:
        run_hybrid(robodyn.load("rp_arm"), **RUN, frame="base_link")
    assert str(caught.value) == (
        "robot 'rp_arm': frame 'base_link' is fixed to the world (no joint moves it), so hybrid force/motion control"
        " on it would have no effect (moving frames: 'link1', 'link2', 'end_effector')."
    )
