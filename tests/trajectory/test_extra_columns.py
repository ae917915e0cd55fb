"""Extra columns of the external torques (``tau_ext``, ``tau_env``) in trajectory files:
written by name, skipped by the trajectory reader, read back by kind."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.exceptions import InputError, TrajectoryError
from robodyn.trajectory import Trajectory, parse_header
from robodyn.trajectory.columns import extra_columns
from robodyn.trajectory.io import read_extra, write_with_extras


def _trajectory() -> Trajectory:
    t = np.linspace(0.0, 0.1, 11)
    q = np.column_stack([np.sin(t), np.cos(t)])
    return Trajectory(t, q, np.cos(t)[:, None] * [1, 0] + [0, 1], np.zeros((11, 2)), np.ones((11, 2)), ["j1", "j2"], "two")


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_tau_ext_and_tau_env_columns_are_written_skipped_by_the_reader_and_read_back_by_kind(tmp_path, suffix):
    trajectory = _trajectory()
    estimate, applied = np.arange(22.0).reshape(11, 2) / 7, -np.arange(22.0).reshape(11, 2) / 3
    path = write_with_extras(tmp_path / f"m{suffix}", trajectory, {"tau_ext": estimate, "tau_env": applied})
    back = Trajectory.load(path)
    assert np.array_equal(back.q, trajectory.q) and np.array_equal(back.tau, trajectory.tau)
    assert np.array_equal(read_extra(path, "tau_ext"), estimate)
    assert np.array_equal(read_extra(path, "tau_env"), applied)
    assert read_extra(path, "G") is None  # negative control: a kind the file does not have
    plain = write_with_extras(tmp_path / f"p{suffix}", trajectory, {})
    assert read_extra(plain, "tau_ext") is None


def test_the_csv_header_names_the_extra_columns_after_the_trajectorys_own(tmp_path):
    path = write_with_extras(tmp_path / "m.csv", _trajectory(), {"tau_ext": np.zeros((11, 2))})
    header = path.read_text(encoding="utf-8").splitlines()[1].split(",")
    assert header[-2:] == ["tau_ext[j1]", "tau_ext[j2]"] and header[:2] == ["t", "q[j1]"]


def test_a_partial_set_of_extra_columns_is_refused_by_name():
    layout = parse_header(["t", "q[a]", "q[b]", "tau_ext[a]"], "f.csv")
    with pytest.raises(TrajectoryError, match=r"tau_ext\[b\]"):
        extra_columns(np.zeros((2, 4)), layout, "tau_ext")


def test_unknown_kinds_and_wrong_shapes_are_refused(tmp_path):
    with pytest.raises(InputError) as raised:
        write_with_extras(tmp_path / "m.csv", _trajectory(), {"tau_oops": np.zeros((11, 2))})
    assert raised.value.argument == "extras"
    with pytest.raises(InputError):
        write_with_extras(tmp_path / "m.csv", _trajectory(), {"tau_ext": np.zeros((10, 2))})
    with pytest.raises(TrajectoryError, match="unknown columns"):
        parse_header(["t", "q[a]", "tau_oops[a]"], "f.csv")  # negative control: only the known kinds are skipped
