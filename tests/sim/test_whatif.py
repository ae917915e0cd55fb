"""Materials, payloads and the what-if sweep; the simulate and whatif commands."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robodyn import InputError
from robodyn.cli.app import main
from robodyn.sim.whatif import sweep
from robodyn.trajectory import Trajectory
from robodyn.urdf.materials import DENSITIES, box_inertia, density
from robodyn.urdf.models import RPArmParameters


def test_densities_and_aliases():
    assert density("plastic") == density("ABS") == 1040.0
    assert density("aluminum") == 2700.0 and density("steel") == 7850.0
    assert density(8000) == 8000.0 and density("8000") == 8000.0
    with pytest.raises(InputError, match="material"):
        density("wood")
    with pytest.raises(InputError):
        density(-1.0)


def test_material_arm_masses_are_density_times_volume():
    p = RPArmParameters.from_material("steel", l1=0.5, l2=0.4, width=0.05)
    assert p.m1 == pytest.approx(7850 * 0.5 * 0.05**2)
    assert p.m2 == pytest.approx(7850 * 0.4 * 0.05**2)
    # The box's inertia about the joint axis through its centre.
    assert p.inertia1 == pytest.approx(box_inertia(p.m1, (0.5, 0.05, 0.05))[1, 1])


def test_without_payload_torques_scale_with_density():
    """Every link's mass and inertia scale with density, so do the torques of one motion."""
    rows = sweep(materials=("abs", "steel"), payloads=(0.0,))
    ratio = DENSITIES["steel"] / DENSITIES["abs"]
    np.testing.assert_allclose(rows[1].peak / rows[0].peak, ratio, rtol=1e-12)
    np.testing.assert_allclose(rows[1].rms / rows[0].rms, ratio, rtol=1e-12)


def test_payload_and_resisting_force_raise_the_torques():
    rows = sweep(materials=("aluminium",), payloads=(0.0, 1.0), forces=((0, 0, 0), (0, 0, -10)))
    free, pushed, loaded, loaded_pushed = rows
    assert np.all(loaded.peak > free.peak) and np.all(pushed.rms > free.rms)
    assert loaded.robot_mass == pytest.approx(free.robot_mass + 1.0)
    # A downward force of 10 N at the tip acts like a payload of 10 / 9.81 kg at rest.
    assert np.all(loaded_pushed.peak > loaded.peak)


def test_whatif_command_prints_the_table_and_writes_the_plot(capsys, tmp_path):
    plot = tmp_path / "whatif.png"
    assert main(["whatif", "--plot", str(plot)]) == 0
    out = capsys.readouterr().out
    assert "steel" in out and "aluminium" in out and "abs" in out and "peak joint1 [N m]" in out
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_whatif_json(capsys):
    assert main(["whatif", "--payloads", "0,1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["rows"]) == 6 and data["torque_units"] == ["N m", "N"]


def test_simulate_command_reaches_the_target_and_writes_files(capsys, tmp_path):
    out, plot = tmp_path / "motion.csv", tmp_path / "motion.png"
    status = main(
        [
            "simulate",
            "rp_arm",
            "--controller",
            "task-space",
            "--target",
            "0.7,0.7",
            "--out",
            str(out),
            "--plot",
            str(plot),
            "--json",
        ]
    )
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["final_error_m"] < 1e-6
    assert len(Trajectory.load(out)) == 3001
    assert plot.stat().st_size > 10_000


def test_failed_simulate_leaves_existing_files_untouched(capsys, tmp_path):
    out = tmp_path / "motion.csv"
    out.write_text("precious")
    status = main(["simulate", "rp_arm", "--controller", "task-space", "--target", "1,2,3,4", "--out", str(out)])
    assert status == 2
    assert out.read_text() == "precious"
    assert "--target must be" in capsys.readouterr().err
