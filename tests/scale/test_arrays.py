"""Objects that travel and Dask: Robot pickling, dask-array dynamics, a 2-worker LocalCluster (slow tier)."""

from __future__ import annotations

import os
import pickle
import signal
import time

import numpy as np
import pytest

import robodyn
from robodyn.dynamics import pickling
from robodyn.dynamics.payload import attach_payload
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.scale.cluster import check_scheduler
from robodyn.sim.simulation import simulate

dask = pytest.importorskip("dask")
da = pytest.importorskip("dask.array")


def _state(robot, count, seed=0):
    rng = np.random.default_rng(seed)
    return robot.random_configuration(rng, count), rng.normal(size=(count, robot.nv)), rng.normal(size=(count, robot.nv))


@pytest.mark.parametrize(
    "make",
    [
        lambda: robodyn.load("panda"),  # mimic finger
        lambda: robodyn.load("solo12"),  # floating base
        lambda: robodyn.load("ur5", gravity=(1.0, -2.0, -9.0), threads=1),
        lambda: robodyn.load("panda", lock={"panda_finger_joint1": 0.013}),  # a locked source
        lambda: attach_payload(robodyn.load("rp_arm"), "end_effector", 1.7),  # an edited source
    ],
)
def test_pickled_robot_gives_equal_torques(make):
    robot = make()
    q, v, a = _state(robot, 20)
    copy = pickle.loads(pickle.dumps(robot))
    assert copy is not robot and copy.name == robot.name and copy.options == robot.options
    np.testing.assert_array_equal(copy.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a))
    np.testing.assert_array_equal(copy.mass_matrix(q), robot.mass_matrix(q))
    np.testing.assert_array_equal(copy.gravity_vector, robot.gravity_vector)
    assert len(pickle.dumps(robot)) < 2 * len(robot.urdf) + 4000  # source and options, no Pinocchio state


def test_unpickling_builds_once_per_process_and_key():
    pickling.clear()
    before = pickling.builds
    robot = robodyn.load("ur5")
    payload = pickle.dumps(robot)
    copies = [pickle.loads(payload) for _ in range(100)]
    assert pickling.builds - before == 1 and all(c is copies[0] for c in copies)
    other = pickle.loads(pickle.dumps(robodyn.load("ur5", gravity=(0, 0, -1.62))))  # the Moon: another key
    assert pickling.builds - before == 2 and other is not copies[0]
    q = _state(robot, 5)[0]
    assert not np.allclose(other.gravity(q), copies[0].gravity(q))  # negative control: options really travel


def test_dask_arrays_equal_numpy():
    import robodyn.scale as scale

    robot = robodyn.load("panda")
    q, v, a = _state(robot, 1000, seed=1)
    lazy = [da.from_array(x, chunks=(c, -1)) for x, c in ((q, 300), (v, 170), (a, 1000))]  # unaligned chunks
    with dask.config.set(scheduler="threads"):
        np.testing.assert_array_equal(scale.inverse_dynamics(robot, *lazy).compute(), robot.inverse_dynamics(q, v, a))
        np.testing.assert_array_equal(scale.mass_matrix(robot, lazy[0]).compute(), robot.mass_matrix(q))
        np.testing.assert_array_equal(scale.gravity(robot, lazy[0]).compute(), robot.gravity(q))
        tau = robot.inverse_dynamics(q, v, a)
        back = scale.forward_dynamics(robot, lazy[0], lazy[1], da.from_array(tau, chunks=(250, -1))).compute()
        np.testing.assert_allclose(back, a, atol=1e-8)  # ABA undoes RNEA
    np.testing.assert_array_equal(scale.inverse_dynamics(robot, q, v, a), robot.inverse_dynamics(q, v, a))  # numpy in, numpy out


def test_dask_errors_name_rows():
    import robodyn.scale as scale

    robot = robodyn.load("solo12")
    q, v, a = _state(robot, 100, seed=2)
    q[63, 3:7] = [1.0, 1.0, 0.0, 0.0]
    with pytest.raises(TrajectoryError, match=r"row 64: q\[3:7\] must be a unit quaternion"):
        scale.inverse_dynamics(robot, da.from_array(q, chunks=(25, -1)), v, a).compute(scheduler="sync")
    with pytest.raises(InputError, match=r"q must be a 2-D array of 19 columns"):
        scale.inverse_dynamics(robot, da.from_array(q[:, :18]), v, a)


@pytest.mark.parametrize("text", ["local:0", "local:65", "local:x", "8786", "http://x y"])
def test_scheduler_spec_refused(text):
    with pytest.raises(InputError, match=r"^scheduler must be"):
        check_scheduler(text)


def test_cli_scheduler_refused_before_work(tmp_path, capsys):
    from robodyn.cli import main

    robot = robodyn.load("rp_arm")
    simulate(robot, np.zeros(2), np.zeros(2), 0.01, 1e-3).save(tmp_path / "m.csv")
    assert main(["torques", "rp_arm", str(tmp_path / "m.csv"), "--scheduler", "local:0"]) == 2
    assert "--scheduler must be local:N" in capsys.readouterr().err


# --------------------------------------------------------------------------------------
# A 2-worker LocalCluster on 127.0.0.1 (slow tier)
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("dask.distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None, silence_logs=40
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    robot = robodyn.load("panda")
    q, v, a = _state(robot, 60_000, seed=4)
    path = tmp_path_factory.mktemp("scale") / "states.npz"
    t = np.arange(len(q)) * 1e-3
    np.savez(path, t=t, q=q, v=v, a=a, q_names=np.array(robot.joint_names), v_names=np.array(robot.joint_names))
    return robot, path


@pytest.mark.slow
def test_cluster_torques_identical_to_local(tmp_path, client, dataset):
    from robodyn.scale.torques import torques_file

    robot, path = dataset
    local = torques_file(robot, path, tmp_path / "local.npz", rows=4096, gravity=True)
    remote = torques_file(robot, path, tmp_path / "remote.npz", rows=4096, gravity=True, client=client)
    assert remote["chunks"] == local["chunks"] == 15
    assert (tmp_path / "local.npz").read_bytes() == (tmp_path / "remote.npz").read_bytes()


@pytest.mark.slow
def test_cluster_dask_arrays_identical_to_local(client, dataset):
    import robodyn.scale as scale

    robot, _ = dataset
    q, v, a = _state(robot, 20_000, seed=6)
    lazy = [da.from_array(x, chunks=(2500, -1)) for x in (q, v, a)]
    np.testing.assert_array_equal(client.compute(scale.inverse_dynamics(robot, *lazy)).result(), robot.inverse_dynamics(q, v, a))
    np.testing.assert_array_equal(client.compute(scale.mass_matrix(robot, lazy[0])).result(), robot.mass_matrix(q))


@pytest.mark.slow
def test_robot_in_100_tasks_is_parsed_once_per_worker(client):
    robot = robodyn.load("z1")
    q, v, a = _state(robot, 3, seed=7)
    before = client.run(lambda: __import__("robodyn.dynamics.pickling", fromlist=["builds"]).builds)
    futures = [client.submit(lambda r, i: (r.inverse_dynamics(q, v, a), os.getpid()), robot, i, pure=False) for i in range(100)]
    results = client.gather(futures)
    after = client.run(lambda: __import__("robodyn.dynamics.pickling", fromlist=["builds"]).builds)
    new = {worker: after[worker] - before.get(worker, 0) for worker in after}
    assert len({pid for _, pid in results}) == 2  # both workers took tasks
    assert sorted(new.values()) == [1, 1]
    for tau, _ in results:
        np.testing.assert_array_equal(tau, robot.inverse_dynamics(q, v, a))


@pytest.mark.slow
def test_a_killed_worker_is_retried(tmp_path, client, dataset):
    from robodyn.scale.torques import torques_file

    robot, path = dataset
    torques_file(robot, path, tmp_path / "local.npz", rows=2000, mass_matrix=True)
    pids = client.run(os.getpid)
    killed = []

    def kill_once(done, total):
        if killed:
            return
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            busy = [worker for worker, keys in client.processing().items() if keys]
            if busy:
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(busy[0])
                return
            time.sleep(0.005)

    torques_file(robot, path, tmp_path / "remote.npz", rows=2000, mass_matrix=True, client=client, progress=kill_once)
    assert killed and killed[0] not in client.run(os.getpid)  # a worker died mid-chunk and was replaced
    assert (tmp_path / "local.npz").read_bytes() == (tmp_path / "remote.npz").read_bytes()


@pytest.mark.slow
def test_cluster_bad_chunk_names_file_and_rows(tmp_path, client):
    from robodyn.scale.torques import torques_file

    robot = robodyn.load("solo12")
    q, v, a = _state(robot, 5000, seed=8)
    q[4321, 3:7] = [0.0, 0.0, 0.0, 2.0]
    np.savez(tmp_path / "bad.npz", t=np.arange(5000) * 1e-3, q=q, v=v, a=a, joint_names=np.array(robot.joint_names))
    with pytest.raises(TrajectoryError, match=r"bad\.npz, row 4322: q\[3:7\] must be a unit quaternion"):
        torques_file(robot, tmp_path / "bad.npz", tmp_path / "out.csv", rows=500, client=client)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.npz"]


@pytest.mark.slow
def test_cluster_sweeps_identical_to_local(client):
    from robodyn.scale import sweeps
    from robodyn.sim.whatif import sweep
    from robodyn.verify.zoo_status import zoo_status

    local = sweep("rp_arm", payloads=(0.0, 1.5), forces=((0, 0, 0), (0, 0, -10)))
    remote = sweeps.sweep("rp_arm", client=client, payloads=(0.0, 1.5), forces=((0, 0, 0), (0, 0, -10)))
    assert len(remote) == len(local) == 12
    for mine, theirs in zip(remote, local, strict=True):
        assert (mine.material, mine.payload) == (theirs.material, theirs.payload)
        np.testing.assert_array_equal(mine.peak, theirs.peak)
        np.testing.assert_array_equal(mine.rms, theirs.rms)
    names = ["double_pendulum", "ur5"]
    assert sweeps.zoo_statuses(client, names) == [zoo_status(name) for name in names]


@pytest.mark.slow
def test_cli_scheduler_local_identical_to_local(tmp_path, capsys):
    from robodyn.cli import main

    robot = robodyn.load("ur5")
    q, v, a = _state(robot, 3000, seed=9)
    np.savez(tmp_path / "m.npz", t=np.arange(3000) * 1e-3, q=q, v=v, a=a, joint_names=np.array(robot.joint_names))
    assert main(["torques", "ur5", str(tmp_path / "m.npz"), "--out", str(tmp_path / "local.parquet"), "--chunk-rows", "500"]) == 0
    remote = ["torques", "ur5", str(tmp_path / "m.npz"), "--out", str(tmp_path / "remote.parquet"), "--chunk-rows", "500"]
    assert main([*remote, "--scheduler", "local:2"]) == 0
    from robodyn.trajectory import Trajectory

    local, distributed = Trajectory.load(tmp_path / "local.parquet"), Trajectory.load(tmp_path / "remote.parquet")
    np.testing.assert_array_equal(distributed.tau, local.tau)
    np.testing.assert_array_equal(distributed.tau, robot.inverse_dynamics(q, v, a))


@pytest.mark.slow
def test_zoo_report_with_a_scheduler_writes_the_same_listing(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[2] / "scripts" / "zoo_report.py"
    only = ["--only", "double_pendulum,ur5,z1"]
    subprocess.run([sys.executable, str(script), *only, "--out", str(tmp_path / "local.md")], check=True)
    subprocess.run([sys.executable, str(script), *only, "--scheduler", "local:2", "--out", str(tmp_path / "dask.md")], check=True)
    listing = (tmp_path / "local.md").read_text()
    assert "| ur5 | pass |" in listing and (tmp_path / "dask.md").read_text() == listing
