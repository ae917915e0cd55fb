"""The simulator against its oracle: every recorded run (tests/sim/oracle_cases.py) gives the
same arrays as the code before the run-plan redesign recorded them (to ≤ 1e-15 of their
scale; most bit for bit), and every run refused then is refused now.

The oracle (``tests/sim/data/sim_oracle.npz``) was recorded once by
``scripts/record_sim_oracle.py`` and is never regenerated. The Pinocchio runs and rp_arm's
compiled runs are fast; the compiled runs of ur5, panda and solo12 compile those robots
(seconds each) and are in the slow tier.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from robodyn.exceptions import RobodynError
from tests.compiled_helpers import shared_cache
from tests.sim.oracle_cases import cases

DATA = Path(__file__).with_name("data")
#: The bar: the largest difference over the array's largest magnitude.
TOLERANCE = 1e-15
FIELDS = ("t", "q", "v", "a", "tau")


@pytest.fixture(scope="module")
def oracle():
    with np.load(DATA / "sim_oracle.npz") as arrays:
        recorded = {key: arrays[key] for key in arrays.files}
    refusals = json.loads((DATA / "sim_oracle_refusals.json").read_text(encoding="utf-8"))
    return recorded, refusals


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's), and every robot loaded on Pinocchio
    (``$ROBODYN_ENGINE``), as when the oracle was recorded: a robot compiled earlier in the
    session would otherwise answer its controller's calls with its kernels (``engine="auto"``)."""
    previous = os.environ.get("ROBODYN_ENGINE")
    os.environ["ROBODYN_ENGINE"] = "pinocchio"
    try:
        with shared_cache() as folder:
            yield folder
    finally:
        if previous is None:
            os.environ.pop("ROBODYN_ENGINE", None)
        else:
            os.environ["ROBODYN_ENGINE"] = previous


def _marks(case) -> list:
    return [pytest.mark.slow] if case.engine == "compiled" and case.robot not in ("rp_arm", "rp_arm_gravity") else []


CASES = [pytest.param(case, id=case.key, marks=_marks(case)) for case in cases()]


def deviation(ours: np.ndarray, theirs: np.ndarray) -> float:
    """``max |ours − theirs| / max(1, max |theirs|)``; infinite for another shape."""
    if ours.shape != theirs.shape:
        return float("inf")
    return float(np.abs(ours - theirs).max(initial=0.0)) / max(1.0, float(np.abs(theirs).max(initial=0.0)))


@pytest.mark.parametrize("case", CASES)
def test_a_run_gives_the_recorded_trajectory(case, oracle):
    recorded, refusals = oracle
    if case.key in refusals:
        with pytest.raises(RobodynError), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            case.run()
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = case.run()
    trajectory, residuals = result if isinstance(result, tuple) else (result, None)
    for field in FIELDS:
        assert deviation(np.asarray(getattr(trajectory, field)), recorded[f"{case.key}:{field}"]) <= TOLERANCE, field
    if residuals is not None:
        assert deviation(residuals, recorded[f"{case.key}:residuals"]) <= TOLERANCE


def test_every_case_was_recorded(oracle):
    recorded, refusals = oracle
    keys = {case.key for case in cases()}
    assert keys == {key.split(":")[0] for key in recorded} | set(refusals)
    assert len(refusals) < len(keys) / 4  # most runs ran (a refusal is the exception)


def test_negative_control_a_changed_gain_is_caught(oracle):
    """The check can fail: the same PD run with a gain 1e-9 off does not match."""
    import robodyn
    from robodyn.sim.control import PDGravity
    from tests.sim.oracle_cases import DT, DURATION, _start

    recorded, _ = oracle
    robot = robodyn.load("rp_arm")
    q0, v0 = _start(robot)
    law = PDGravity(robot, q0 + 0.1, kp=np.linspace(30.0, 60.0, 2) * (1 + 1e-9), kd=np.linspace(3.0, 6.0, 2))
    trajectory = robodyn.simulate(robot, q0, v0, DURATION, DT, controller=law, engine="pinocchio", limits="ignore")
    assert deviation(trajectory.q, recorded["rp_arm/pd/pinocchio/rk4:q"]) > TOLERANCE
