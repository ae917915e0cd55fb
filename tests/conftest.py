"""Shared fixtures: the URDFs of ``urdf/``, a few zoo robots, seeded random states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
URDF_FILES = sorted((ROOT / "urdf").glob("*.urdf"))
#: Robots that are not degenerate where bugs live (tests/data/robots): mimic joints with
#: multipliers other than ±1 and offsets, oblique non-unit axes, six-valued origins.
NONDEGENERATE = ROOT / "tests" / "data" / "robots"
#: name -> (URDF, load options): those robots fixed, floating (tilted in the states drawn by
#: ``random_states``) and with joints locked at non-zero positions, negative ones included.
NONDEGENERATE_CASES = {
    "oblique": (NONDEGENERATE / "oblique.urdf", {}),
    "oblique_floating": (NONDEGENERATE / "oblique.urdf", {"floating_base": True}),
    "oblique_locked": (NONDEGENERATE / "oblique.urdf", {"lock": {"j_twist": 0.7, "j_extend": 0.13}}),
    "oblique_locked_negative": (NONDEGENERATE / "oblique.urdf", {"lock": {"j_extend": -0.08, "j_tool": -1.1}}),
    "gripper": (NONDEGENERATE / "mimic_gripper.urdf", {}),
    "gripper_floating": (NONDEGENERATE / "mimic_gripper.urdf", {"floating_base": True}),
    "gripper_locked_sources": (NONDEGENERATE / "mimic_gripper.urdf", {"lock": {"j_rotate": 0.6, "j_left": 0.03}}),
    "gripper_locked_prismatic": (NONDEGENERATE / "mimic_gripper.urdf", {"lock": {"j_left": -0.015}}),
    "mimic_tree": (NONDEGENERATE / "mimic_tree.urdf", {}),
    "mimic_tree_floating": (NONDEGENERATE / "mimic_tree.urdf", {"floating_base": True}),
    "mimic_tree_locked": (NONDEGENERATE / "mimic_tree.urdf", {"lock": {"j_shoulder": 0.5, "j_slide": 0.07}}),
}
#: Zoo robots used by the fast tier: a spread of joint types and sizes.
FAST_ZOO = ["panda", "ur5", "double_pendulum_continuous", "so100", "z1"]


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261123)


def random_states(robot, rng: np.random.Generator, count: int = 4):
    """``count`` random states (one a row); a floating base's first one gets an explicit
    tilted, yawed pose (not the identity orientation)."""
    q = robot.random_configuration(rng, count)
    if robot.floating_base:
        q[0] = robot.floating_configuration([0.3, -0.2, 0.5], [0.4, -0.3, 0.9], q[0, 7:])
        assert abs(q[0, 6]) < 0.99
    return q, rng.normal(size=(count, robot.nv)), rng.normal(size=(count, robot.nv))


def random_state(robot, rng: np.random.Generator, count: int | None = None):
    """A configuration within limits and random velocity and acceleration."""
    q = robot.random_configuration(rng, count)
    shape = (robot.nv,) if count is None else (count, robot.nv)
    return q, rng.normal(size=shape), rng.normal(size=shape)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--differential-seed GENERATOR:SEED`` replays one case of the differential harness
    (tests/differential; the same as ``ROBODYN_DIFFERENTIAL_SEED=GENERATOR:SEED``)."""
    parser.addoption(
        "--differential-seed",
        metavar="GENERATOR:SEED",
        help="run the differential harness on this one case only (e.g. random_tree:1002)",
    )


def pytest_configure(config: pytest.Config) -> None:
    import os
    import tempfile

    # One compile cache for the compiled-engine tests of the whole session
    # (tests/compiled_helpers.py): made here, in the process that starts the session, whose
    # environment the pytest-xdist workers inherit; a robot built by one worker is found by
    # the other instead of being derived and compiled a second time.
    if "PYTEST_XDIST_WORKER" not in os.environ and not os.environ.get("ROBODYN_TEST_SESSION_CACHE"):
        folder = tempfile.mkdtemp(prefix="robodyn-test-cache-")
        os.environ["ROBODYN_TEST_SESSION_CACHE"] = folder
        config.add_cleanup(lambda: _remove_session_cache(folder))
    # What a robot's single calls run on must not depend on what the compile cache holds
    # (a machine that compiled rp_arm before would answer with its kernels): Pinocchio,
    # unless a test asks for engine="auto" itself (tests/compiled/test_engine.py).
    os.environ.setdefault("ROBODYN_ENGINE", "pinocchio")
    seed = config.getoption("--differential-seed", default=None)
    if seed:
        os.environ["ROBODYN_DIFFERENTIAL_SEED"] = seed


def _remove_session_cache(folder: str) -> None:
    import os
    import shutil

    shutil.rmtree(folder, ignore_errors=True)
    if os.environ.get("ROBODYN_TEST_SESSION_CACHE") == folder:
        del os.environ["ROBODYN_TEST_SESSION_CACHE"]
