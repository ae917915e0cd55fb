"""Throughput of panda inverse dynamics: local threads vs a LocalCluster, overhead per chunk,
and the memory peak of ``robodyn torques`` on a file larger than its memory limit.

Run from the repository root: ``python scripts/scale_bench.py [--states 10000000] [--workers 2] [--memory]``.
Each part runs well under a minute on a 2-core machine; the numbers go to stdout as a
markdown table (docs/scale.md quotes them).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

import robodyn


def states(robot, count: int, seed: int):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, (count, robot.nq)), rng.normal(size=(count, robot.nv)), rng.normal(size=(count, robot.nv))


def local_threads(total: int, chunk: int) -> float:
    """States/s of Robot.inverse_dynamics on 2-D arrays (Pinocchio's threads), data made outside the clock."""
    robot = robodyn.load("panda")
    elapsed = 0.0
    for index in range(0, total, chunk):
        q, v, a = states(robot, min(chunk, total - index), index)
        started = time.perf_counter()
        robot.inverse_dynamics(q, v, a)
        elapsed += time.perf_counter() - started
    return total / elapsed


def cluster_rates(client, total: int, chunks: list[int]) -> list[tuple[int, int, float]]:
    """States/s for each chunk size: the states are made and kept on the workers first (not
    timed), then only the dynamics and the sums that come back are timed."""
    import dask.array as da
    from dask.distributed import wait

    import robodyn.scale as scale

    robot = robodyn.load("panda", threads=1)  # one Pinocchio thread a worker process
    rows = []
    for chunk in chunks:
        count = total // chunk * chunk
        q = da.random.default_rng(0).uniform(-1, 1, (count, robot.nq), chunks=(chunk, -1))
        v = da.random.default_rng(1).normal(size=(count, robot.nv), chunks=(chunk, -1))
        a = da.random.default_rng(2).normal(size=(count, robot.nv), chunks=(chunk, -1))
        q, v, a = client.persist([q, v, a])
        wait([q, v, a])
        client.compute(scale.inverse_dynamics(robot, q[:chunk], v[:chunk], a[:chunk]).sum()).result()  # robot built
        started = time.perf_counter()
        client.compute(scale.inverse_dynamics(robot, q, v, a).sum()).result()
        rows.append((chunk, count // chunk, count / (time.perf_counter() - started)))
        del q, v, a
    return rows


def empty_task_overhead(client, count: int = 2000) -> float:
    """Seconds a task of the scheduler round trip (tiny tasks, results gathered)."""
    started = time.perf_counter()
    client.gather(client.map(int, range(count), pure=False))
    return (time.perf_counter() - started) / count


def memory_peak(folder: Path, limit_mb: int, rows: int) -> dict:
    """Peak RSS of `robodyn torques` on an NPZ larger than an RLIMIT_AS of ``limit_mb``."""
    make = textwrap.dedent(
        f"""
        import numpy as np, robodyn
        from robodyn.scale.datasets import DatasetWriter
        robot = robodyn.load("panda")
        names = [f"q[{{j}}]" for j in robot.joint_names]
        header = ["t", *names, *(n.replace("q[", k + "[") for k in ("v", "a") for n in names)]
        arrays = {{"t": (np.array([0]), ()), "q": (np.arange(1, 9), (8,)), "v": (np.arange(9, 17), (8,)), "a": (np.arange(17, 25), (8,))}}
        writer = DatasetWriter({str(folder / "big.npz")!r}, header, length={rows}, arrays=arrays)
        rng = np.random.default_rng(0)
        for start in range(0, {rows}, 200_000):
            n = min(200_000, {rows} - start)
            writer.write(np.column_stack([(start + np.arange(n)) * 1e-3, rng.uniform(-1, 1, (n, 8)), rng.normal(size=(n, 16))]))
        writer.close(small={{"q_names": np.array(robot.joint_names), "v_names": np.array(robot.joint_names)}})
        """
    )
    subprocess.run([sys.executable, "-c", make], check=True)
    run = textwrap.dedent(
        f"""
        import resource, sys, time
        resource.setrlimit(resource.RLIMIT_AS, ({limit_mb} * 2**20, {limit_mb} * 2**20))
        from robodyn.cli import main
        started = time.perf_counter()
        code = main(["torques", "panda", {str(folder / "big.npz")!r}, "--out", {str(folder / "tau.npz")!r}, "--json"])
        print("result", time.perf_counter() - started, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)
        sys.exit(code)
        """
    )
    done = subprocess.run([sys.executable, "-c", run], capture_output=True, text=True, check=True)
    seconds, peak_kb = done.stderr.split("result")[1].split()[:2]
    return {
        "file_MB": (folder / "big.npz").stat().st_size / 2**20,
        "limit_MB": limit_mb,
        "peak_rss_MB": int(peak_kb) / 1024,
        "seconds": float(seconds),
        "samples": json.loads(done.stdout)["samples"],
    }


def rss_by_size(folder: Path, suffix: str, sizes: list[int]) -> list[dict]:
    """Peak RSS of `robodyn torques` (same format in and out) for files of several sizes."""
    results = []
    for rows in sizes:
        source, out = folder / f"in{suffix}", folder / f"out{suffix}"
        make = textwrap.dedent(
            f"""
            import numpy as np, robodyn
            from robodyn.scale.datasets import DatasetWriter
            robot = robodyn.load("panda")
            names = [f"q[{{j}}]" for j in robot.joint_names]
            header = ["t", *names, *(n.replace("q[", k + "[") for k in ("v", "a") for n in names)]
            writer = DatasetWriter({str(source)!r}, header, length={rows}, robot="panda")
            rng = np.random.default_rng(0)
            for start in range(0, {rows}, 50_000):
                n = min(50_000, {rows} - start)
                writer.write(np.column_stack([(start + np.arange(n)) * 1e-3, rng.uniform(-1, 1, (n, 8)), rng.normal(size=(n, 16))]))
            writer.close()
            """
        )
        subprocess.run([sys.executable, "-c", make], check=True)
        run = textwrap.dedent(
            f"""
            import resource, sys, time
            from robodyn.cli import main
            started = time.perf_counter()
            code = main(["torques", "panda", {str(source)!r}, "--out", {str(out)!r}, "--json"])
            print("result", time.perf_counter() - started, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)
            sys.exit(code)
            """
        )
        done = subprocess.run([sys.executable, "-c", run], capture_output=True, text=True, check=True)
        seconds, peak_kb = done.stderr.split("result")[1].split()[:2]
        results.append(
            {
                "format": suffix,
                "rows": rows,
                "file_MB": source.stat().st_size / 2**20,
                "peak_rss_MB": int(peak_kb) / 1024,
                "seconds": float(seconds),
            }
        )
        source.unlink()
        out.unlink()
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000_000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cluster-states", type=int, help="states kept on the workers (default --states; 200 B each)")
    parser.add_argument("--memory", action="store_true", help="also measure the memory peak (writes ~1 GB to a temporary folder)")
    arguments = parser.parse_args()
    print(f"machine: {os.cpu_count()} cores; panda, {arguments.states:,} states\n")
    rate = local_threads(arguments.states, 1_000_000)
    print(f"| local, Robot.inverse_dynamics (Pinocchio threads) | {rate:,.0f} states/s |")
    from dask.distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=arguments.workers, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, silence_logs=40
        ) as cluster,
        Client(cluster) as client,
    ):
        print(f"| scheduler round trip, empty task | {empty_task_overhead(client) * 1e3:.2f} ms a task |")
        rows = cluster_rates(client, arguments.cluster_states or arguments.states, [250_000, 25_000, 2_500])
        for chunk, count, states_per_s in rows:
            print(f"| LocalCluster {arguments.workers}×1 thread, {count} chunks of {chunk:,} | {states_per_s:,.0f} states/s |")
        (c1, n1, r1), (_, n2, r2) = rows[0], rows[-1]
        total = n1 * c1
        overhead = (total / r2 - total / r1) / (n2 - n1)
        print(f"| overhead a chunk, from the two extremes | {overhead * 1e3:.2f} ms |")
    if arguments.memory:
        with tempfile.TemporaryDirectory(dir=".") as folder:
            print(json.dumps(memory_peak(Path(folder), 400, 2_600_000)))
            for suffix, sizes in ((".parquet", [200_000, 1_600_000]), (".csv", [140_000, 280_000])):
                for row in rss_by_size(Path(folder), suffix, sizes):
                    print(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
