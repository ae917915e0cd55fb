"""What the README's pictures show, not only the hash of the code that drew them.

``tests/integration/test_pictures.py`` checks that docs/pictures.json's hashes match the
drawing code and the PNGs; a change in what is drawn that keeps the code (the data, a
library) passes it. Here the what-if picture is drawn again from the data and compared
with the committed PNG pixel by pixel, its bars with the numbers of the sweep, and the
poster's run (the demo) with what its caption says: the end effector reaches the target.
"""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.image import imread

import robodyn
from tests.conftest import ROOT

pytestmark = pytest.mark.differential


@pytest.fixture(scope="module")
def whatif():
    from robodyn.sim.whatif import sweep

    robot = robodyn.load("rp_arm")
    rows = sweep("rp_arm", forces=((0.0, 0.0, 0.0), (0.0, 0.0, -10.0)))
    return robot, rows


def _figure(robot, rows):
    from robodyn.viz.plots import whatif_figure

    return whatif_figure(rows, robot.joint_names, [dof.effort_unit for dof in robot.dofs],
                         effort_limits=[joint.effort for joint in robot.joints])  # fmt: skip


def bars_show(figure, rows) -> None:
    """Each joint's axis has one peak bar and one RMS bar a variant, as tall as the data."""
    axes = [axis for axis in figure.axes if axis.patches]
    assert len(axes) == len(rows[0].peak)
    for index, axis in enumerate(axes):
        heights = [patch.get_height() for patch in axis.patches]
        expected = [row.peak[index] for row in rows] + [row.rms[index] for row in rows]
        np.testing.assert_allclose(heights, expected, rtol=1e-12, err_msg=f"joint {index}")


def test_the_whatif_bars_are_the_sweep_numbers(whatif):
    robot, rows = whatif
    figure = _figure(robot, rows)
    bars_show(figure, rows)
    # The force pushes down on the end effector: a heavier load on the first joint.
    assert rows[1].peak[0] > rows[0].peak[0]
    from dataclasses import replace

    wrong = [replace(rows[0], peak=rows[0].peak * 1.1), *rows[1:]]  # negative control
    with pytest.raises(AssertionError):
        bars_show(figure, wrong)


@pytest.mark.slow
def test_the_committed_whatif_picture_is_the_figure_drawn_now(whatif, tmp_path):
    from robodyn.viz.plots import save_png

    robot, rows = whatif
    path = save_png(_figure(robot, rows), tmp_path / "whatif.png")
    committed = imread(ROOT / "docs" / "rp_arm_whatif.png")
    differing = _differing(committed, imread(path))
    assert differing < 0.002, f"{differing:.2%} of the pixels differ from docs/rp_arm_whatif.png"
    other = [rows[1], rows[0]]  # negative control: the variants swapped
    path = save_png(_figure(robot, other), tmp_path / "swapped.png")
    assert _differing(committed, imread(path)) > 0.002


def _differing(first: np.ndarray, second: np.ndarray) -> float:
    """The fraction of pixels that differ (1 for images of different sizes)."""
    if first.shape != second.shape:
        return 1.0
    return float(np.mean(np.any(np.abs(first - second) > 0.1, axis=-1)))


def test_the_poster_run_reaches_its_target():
    """The poster shows the demo's run: the end effector at the target (0.7, 0.7) within 1 mm."""
    from robodyn.sim.experiment import run_simulation

    robot = robodyn.load("rp_arm")
    trajectory, summary = run_simulation(
        robot, controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1], duration=1.0
    )
    reached = robot.frame_position(trajectory.q[-1], robot.end_effector)
    target = np.asarray(summary["target_m"], dtype=float)
    assert np.linalg.norm(reached[[0, 2]] - target[[0, 2]] if target.size == 3 else reached[:2] - target) < 1e-3, (
        reached,
        target,
    )
