"""Figures read back: the right columns, the right units, limits drawn, no text collisions."""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure

import robodyn
from robodyn.sim.experiment import run_simulation
from robodyn.sim.whatif import sweep
from robodyn.viz.plots import plot_simulation, simulation_figure, text_overlaps, whatif_figure


def _run(name: str, **options):
    robot = robodyn.load(name, floating_base=name == "solo12")
    trajectory, summary = run_simulation(robot, duration=0.4, dt=2e-3, **options)
    target = np.asarray(summary["target_m"]) if "target_m" in summary else None
    return robot, trajectory, options.get("frame"), target


@pytest.fixture(scope="module")
def runs():
    return {
        "rp_arm": _run("rp_arm", controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1]),
        "panda": _run("panda", q0=[0.1, -0.4, 0.2, -2.0, 0.3, 1.6, 0.5, 0.02]),
        "solo12": _run("solo12"),
    }


def _figure_of(runs, name) -> tuple:
    robot, trajectory, frame, target = runs[name]
    return robot, trajectory, simulation_figure(robot, trajectory, frame=frame, target=target)


def unit_problems(figure: Figure, robot) -> list[str]:
    """Each joint's curve sits on an axis whose quantity and unit fit its URDF type."""
    problems = []
    for axis in figure.axes:
        ylabel = axis.get_ylabel().replace("\n", " ")
        for line in axis.get_lines():
            joint = robot.spec.joints.get(line.get_label())
            if joint is None:
                continue
            linear = joint.type == "prismatic"
            allowed = ("position [m]", "force [N]") if linear else ("position [rad]", "torque [N m]")
            if not any(ylabel.endswith(a) for a in allowed):
                problems.append(f"{joint.name} ({joint.type}) drawn on {ylabel!r}")
    return problems


def whatif_unit_problems(figure: Figure, robot) -> list[str]:
    problems = []
    for axis, name in zip(figure.axes, robot.joint_names, strict=True):
        linear = robot.spec.joints[name].type == "prismatic"
        expected = f"{name} {'force [N]' if linear else 'torque [N m]'}"
        if axis.get_ylabel().replace("\n", " ") != expected:
            problems.append(f"{axis.get_ylabel()!r} for {name}")
    return problems


@pytest.mark.parametrize("name", ["rp_arm", "panda", "solo12"])
def test_simulation_figure_has_no_colliding_text_and_right_units(runs, name):
    robot, _trajectory, figure = _figure_of(runs, name)
    assert text_overlaps(figure) == []
    assert unit_problems(figure, robot) == []


def column_problems(figure: Figure, robot, trajectory) -> list[str]:
    """Each joint's curve equals its trajectory column (by Pinocchio's idx_q / idx_v), and
    every moving joint has its position and its effort curve."""
    model = robot.model
    problems, seen = [], set()
    for axis in figure.axes:
        quantity = axis.get_ylabel().split(" [")[0]
        for line in axis.get_lines():
            label = line.get_label()
            if label not in robot.spec.joints:
                continue
            joint_id = model.getJointId(label)
            column = (
                trajectory.q[:, model.idx_qs[joint_id]] if quantity == "position" else trajectory.tau[:, model.idx_vs[joint_id]]
            )
            if not (np.array_equal(line.get_xdata(), trajectory.t) and np.array_equal(line.get_ydata(), column)):
                problems.append(f"{label} {quantity}")
            seen.add((label, quantity))
    for joint in robot.joints:
        if joint.type == "floating":
            continue
        for quantity in ("position", "force" if joint.type == "prismatic" else "torque"):
            if (joint.name, quantity) not in seen:
                problems.append(f"{joint.name} {quantity} missing")
    return problems


@pytest.mark.parametrize("name", ["rp_arm", "panda", "solo12"])
def test_plotted_curves_are_the_trajectory_columns(runs, name):
    robot, trajectory, figure = _figure_of(runs, name)
    assert column_problems(figure, robot, trajectory) == []
    if robot.floating_base:  # the old bug: a joint curve was the base height
        moving = {j.name for j in robot.joints if j.type != "floating"}
        curves = [line.get_ydata() for axis in figure.axes for line in axis.get_lines() if line.get_label() in moving]
        assert not any(np.array_equal(c, trajectory.q[:, 2]) for c in curves)


def test_column_checker_finds_the_old_offset_bug(runs):  # negative control
    robot, trajectory, figure = _figure_of(runs, "solo12")
    offset = robot.nq - robot.nv  # the old code drew column index + nq - nv
    for axis in figure.axes:
        for line in axis.get_lines():
            if line.get_label() in robot.spec.joints and axis.get_ylabel().startswith("position"):
                index = robot.joint_names.index(line.get_label())
                line.set_ydata(trajectory.q[:, index + offset])
    assert len(column_problems(figure, robot, trajectory)) == 12


def test_hostile_joint_names_are_drawn_literally():
    urdf = """<robot name="r$x$"><link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="b"><inertial><origin xyz="0 0 0.3"/><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j$\\frac{1}{0}$&#x9b;[31m" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0.6 0.8"/>
      <limit lower="-1" upper="1" effort="5" velocity="2"/></joint></robot>"""
    robot = robodyn.load(urdf)
    trajectory, _ = run_simulation(robot, duration=0.1, dt=1e-2, q0=[0.2])
    figure = simulation_figure(robot, trajectory)
    assert text_overlaps(figure) == []  # draws (no mathtext error)
    texts = [t.get_text() for legend in figure.legends for t in legend.get_texts()]
    assert "j\\$\\frac{1}{0}\\$?[31m" in texts


def test_limits_are_drawn_as_bands(runs):
    robot, _trajectory, figure = _figure_of(runs, "rp_arm")
    slider = robot.spec.joints["joint2"]
    axis = next(a for a in figure.axes if a.get_ylabel() == "position [m]")
    dashed = {round(float(line.get_ydata()[0]), 9) for line in axis.get_lines() if line.get_linestyle() == "--"}
    assert {slider.lower, slider.upper} <= dashed
    assert axis.patches, "no band"
    effort = next(a for a in figure.axes if a.get_ylabel() == "torque [N m]")
    limit = robot.spec.joints["joint1"].effort
    assert {-limit, limit} <= {float(line.get_ydata()[0]) for line in effort.get_lines() if line.get_linestyle() == "--"}


def test_overlap_checker_finds_collisions():  # negative control
    figure = Figure(figsize=(4, 3))
    axis = figure.subplots()
    axis.plot([0, 1], [0, 1], label="a curve")
    axis.set_xticks([0.0, 0.02], ["aluminium", "aluminium"])
    assert any("x tick" in a and "x tick" in b for a, b in text_overlaps(figure))
    figure = Figure(figsize=(4, 3))
    axis = figure.subplots()
    axis.plot([0, 1], [0, 1], label="a curve")
    axis.legend(loc="center")
    assert any("legend" in a and "data" in b for a, b in text_overlaps(figure))
    figure = Figure(figsize=(4, 3))
    axis = figure.subplots()
    axis.set_title("title")
    axis.text(0.5, 1.02, "on the title", transform=axis.transAxes, ha="center")
    assert text_overlaps(figure)


def test_unit_checker_finds_swapped_units(runs):  # negative control
    robot, _trajectory, figure = _figure_of(runs, "rp_arm")
    by_label = {a.get_ylabel(): a for a in figure.axes}
    by_label["torque [N m]"].set_ylabel("force [N]")
    by_label["force [N]"].set_ylabel("torque [N m]")
    assert len(unit_problems(figure, robot)) == 2


@pytest.mark.parametrize("crowded", [False, True])
def test_whatif_figure_is_clean_with_forces_in_newton(crowded):
    robot = robodyn.load("rp_arm")
    options = {"materials": ("abs", "aluminium", "steel", "2000"), "forces": ((0, 0, 0), (1.0, 0, -5.0))} if crowded else {}
    rows = sweep("rp_arm", duration=0.5, **options)
    units = [dof.effort_unit for dof in robot.dofs]
    figure = whatif_figure(rows, robot.joint_names, units, effort_limits=[j.effort for j in robot.joints])
    assert text_overlaps(figure) == []
    assert whatif_unit_problems(figure, robot) == []
    for axis, column in zip(figure.axes, range(robot.nv), strict=True):
        heights = [bar.get_height() for bar in axis.patches]
        np.testing.assert_allclose(heights[: len(rows)], [r.peak[column] for r in rows])
        np.testing.assert_allclose(heights[len(rows) :], [r.rms[column] for r in rows])
    swapped = whatif_figure(rows, robot.joint_names, units[::-1])
    assert len(whatif_unit_problems(swapped, robot)) == 2  # negative control


def test_figures_change_no_global_matplotlib_state(runs, tmp_path, monkeypatch):
    backend = matplotlib.get_backend()
    monkeypatch.setattr(matplotlib, "use", lambda *a, **k: pytest.fail("matplotlib.use called"))
    robot, trajectory, frame, target = runs["rp_arm"]
    path = plot_simulation(robot, trajectory, tmp_path / "sim.png", frame=frame, target=target)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert matplotlib.get_backend() == backend
    import sys

    if "matplotlib.pyplot" in sys.modules:
        assert sys.modules["matplotlib.pyplot"].get_fignums() == []


# --------------------------------------------------------------------------------------
# Issue 29: The what-if figure is scaled to its bars, with the effort limit as a line (issue
# --------------------------------------------------------------------------------------
def _rows(peaks):
    return [
        SimpleNamespace(material=m, payload=0.0, force=np.zeros(3), peak=np.array(p), rms=0.6 * np.array(p))
        for m, p in zip(("abs", "aluminium", "steel"), peaks, strict=True)
    ]


def test_bars_far_below_the_limit_fill_their_axis_and_the_limit_is_named():
    # a kuka-like sweep: 300 N m limits, peaks of 4 to 40 N m
    rows = _rows([[12.0, 4.0], [20.0, 6.0], [40.0, 9.0]])
    figure = whatif_figure(rows, ["a1", "a2"], ["N m", "N m"], effort_limits=[300.0, 300.0])
    for axis, top in zip(figure.axes[:2], (40.0, 9.0), strict=True):
        low, high = axis.get_ylim()
        assert low == 0.0 and top <= high <= 1.3 * top  # the tallest bar fills most of the axis
        assert any("limit 300 N m" in text.get_text() for text in axis.texts)
    legend = figure.legends[0]
    assert "effort limit" in [t.get_text() for t in legend.get_texts()]
    assert text_overlaps(figure) == []


def test_a_limit_near_the_bars_is_a_dashed_line_inside_the_axis():
    rows = _rows([[80.0], [90.0], [95.0]])
    figure = whatif_figure(rows, ["a1"], ["N m"], effort_limits=[100.0])
    axis = figure.axes[0]
    lines = [line for line in axis.get_lines() if line.get_linestyle() == "--" and len(line.get_ydata())]
    assert [float(line.get_ydata()[0]) for line in lines] == [100.0]
    assert axis.get_ylim()[1] > 100.0 and not axis.texts
