"""Gymnasium's ant and half_cheetah (MJCF as shipped, contacts and limits from the file)
dropped for 2 s on their floor, against MuJoCo brought to robodyn's model
(scripts/gymnasium_ground.py: rigid contacts and limits, no margin, no springs). The files
come from Gymnasium's wheel on PyPI into a cache directory; offline, skipped."""

from __future__ import annotations

import importlib.util

import pytest

from tests.conftest import ROOT

pytest.importorskip("mujoco")
spec = importlib.util.spec_from_file_location("gymnasium_ground", ROOT / "scripts" / "gymnasium_ground.py")
assert spec is not None and spec.loader is not None
drops = importlib.util.module_from_spec(spec)
spec.loader.exec_module(drops)


@pytest.fixture(scope="module")
def assets():
    folder = drops.assets()
    if folder is None:
        pytest.skip(f"gymnasium {drops.VERSION}'s wheel is not cached and cannot be downloaded (offline)")
    return folder


@pytest.mark.slow
def test_half_cheetah_rests_on_its_feet_and_stops_where_mujoco_rests_it(assets):
    figures = drops.compare(assets / "half_cheetah.xml")
    assert figures["height apart [m]"] < 1e-3 and figures["attitude apart [rad]"] < 1e-3
    assert figures["joints apart [rad]"] < 2e-2  # the feet rest on friction: statically indeterminate
    assert figures["same contact set"] == 1.0 and figures["mean normal error"] < 1e-9
    assert figures["deepest past a limit [rad]"] < 1e-9


@pytest.mark.slow
def test_ants_ankles_rest_on_their_stops_where_mujoco_holds_them(assets):
    figures = drops.compare(assets / "ant.xml")
    assert figures["height apart [m]"] < 1e-4 and figures["attitude apart [rad]"] < 1e-3
    assert figures["joints apart [rad]"] < 1e-3
    assert figures["same contact set"] == 1.0
    assert figures["mean normal error"] < 2e-2  # 4e-16 measured; 7e-3 where the polish fails on the redundant feet and stops
    assert figures["deepest past a limit [rad]"] < 1e-4


@pytest.mark.slow
def test_without_enforced_limits_the_ants_ankles_fold_through_their_stops(assets):
    figures = drops.compare(assets / "ant.xml", limits="warn")
    assert figures["deepest past a limit [rad]"] > 0.1 and figures["height apart [m]"] > 0.05  # 0.29 rad, 0.11 m
    assert figures["same contact set"] == 0.0  # the torso lies on the floor
