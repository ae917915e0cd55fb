"""Benchmarks: where robodyn stands against raw Pinocchio, measured in the same run.

Run ``make bench`` (or ``python scripts/bench.py [--quick]``). Every figure is the median
of repeats; every comparison is a ratio of two figures measured here, now, on the same
model. Writes ``bench/results.json`` and ``bench/results.md``.

Sections:
    single   per-call cost of robodyn's methods vs the raw ``pin.*`` call
    batch    100 000 states: robodyn vs a Python loop over pin.rnea / pin.aba, and vs
             Pinocchio's parallel API called directly
    reference  the independent reference's numeric mode, states/s, vs Pinocchio
    symbolic   symbolic derivation time and operation counts against the targets of #17
    codegen    generated Python code's evaluation cost vs Pinocchio
    simulation real-time factor of 10 s of panda at 1 kHz
    recording  time and HTML size of a 10 s panda recording at 30 fps
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import statistics
import sys
import time
import timeit
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin

import robodyn
from robodyn import reference
from robodyn.sim.simulation import SimulationError, simulate

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "bench"
PANDA_ARM = {"lock": {"panda_finger_joint1": 0.0}}


def paired(ours: Callable[[], object], raw: Callable[[], object], repeats: int = 15) -> tuple[float, float, float]:
    """Median times of two functions measured alternately, and the median of their ratios.

    Alternating the two in each repeat keeps frequency changes and other load from
    favouring either side.
    """
    timers = timeit.Timer(ours), timeit.Timer(raw)
    number = max(1, int(timers[1].autorange()[0] * 0.1))
    ours_times, raw_times = [], []
    for _ in range(repeats):
        ours_times.append(timers[0].timeit(number) / number)
        raw_times.append(timers[1].timeit(number) / number)
    ratios = [o / r for o, r in zip(ours_times, raw_times, strict=True)]
    return statistics.median(ours_times), statistics.median(raw_times), statistics.median(ratios)


def median_once(function: Callable[[], object], repeats: int = 3) -> float:
    """Median wall time of ``repeats`` whole runs of a long function."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def bench_single(quick: bool) -> list[dict]:
    rows = []
    for name in ("panda", "ur5", "rp_arm"):
        robot = robodyn.load(name)
        model, data = robot.model, robot.model.createData()
        rng = np.random.default_rng(0)
        q = robot.random_configuration(rng).copy()
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        tau = robot.inverse_dynamics(q, v, a)
        cases = {
            "inverse_dynamics": (lambda: robot.inverse_dynamics(q, v, a), lambda: pin.rnea(model, data, q, v, a)),
            "mass_matrix": (lambda: robot.mass_matrix(q), lambda: pin.crba(model, data, q)),
            "coriolis_matrix": (lambda: robot.coriolis_matrix(q, v), lambda: pin.computeCoriolisMatrix(model, data, q, v)),
            "gravity": (lambda: robot.gravity(q), lambda: pin.computeGeneralizedGravity(model, data, q)),
        }
        if robot.mimic is None:
            cases["forward_dynamics"] = (lambda: robot.forward_dynamics(q, v, tau), lambda: pin.aba(model, data, q, v, tau))
        if robot.mimic is not None:
            cases["forward_dynamics (mimic: CRBA + solve)"] = (
                lambda: robot.forward_dynamics(q, v, tau),
                lambda: np.linalg.solve(pin.crba(model, data, q), tau - pin.nonLinearEffects(model, data, q, v)),
            )
        for method, (ours, raw) in cases.items():
            ours_s, raw_s, ratio = paired(ours, raw)
            rows.append(
                {"robot": name, "method": method, "robodyn_us": ours_s * 1e6, "pinocchio_us": raw_s * 1e6, "ratio": ratio}
            )
    return rows


def bench_batch(quick: bool) -> list[dict]:
    count = 20_000 if quick else 100_000
    robot = robodyn.load("panda", **PANDA_ARM)
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(1)
    q = robot.random_configuration(rng, count)
    v, a = rng.normal(size=(2, count, robot.nv))
    tau = robot.inverse_dynamics(q, v, a)
    threads = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    pool = pin.ModelPool(model, threads)
    qt, vt, at, taut = (np.ascontiguousarray(x.T) for x in (q, v, a, tau))

    def loop(function, third):
        return lambda: [function(model, data, q[i], v[i], third[i]) for i in range(count)]

    rows = []
    for name, ours, python_loop, parallel in (
        (
            "inverse_dynamics",
            lambda: robot.inverse_dynamics(q, v, a),
            loop(pin.rnea, a),
            lambda: pin.rneaInParallel(threads, pool, qt, vt, at),
        ),
        (
            "forward_dynamics",
            lambda: robot.forward_dynamics(q, v, tau),
            loop(pin.aba, tau),
            lambda: pin.abaInParallel(threads, pool, qt, vt, taut),
        ),
    ):
        ours_s, loop_s, parallel_s = median_once(ours), median_once(python_loop), median_once(parallel)
        rows.append(
            {
                "robot": "panda (arm, fingers locked)",
                "method": name,
                "states": count,
                "threads": threads,
                "robodyn_states_per_s": count / ours_s,
                "python_loop_states_per_s": count / loop_s,
                "raw_parallel_states_per_s": count / parallel_s,
                "speedup_vs_loop": loop_s / ours_s,
                "ratio_to_raw_parallel": parallel_s / ours_s,
            }
        )
    return rows


def bench_reference(quick: bool) -> list[dict]:
    rows = []
    for name in ("panda", "ur5"):
        robot, model = robodyn.load(name), reference.load(name)
        count = 2_000 if quick else 10_000
        rng = np.random.default_rng(2)
        q = robot.random_configuration(rng, count)
        order = [robot.joint_names.index(j) for j in model.joint_names]
        qr = q[:, order]
        v, a = rng.normal(size=(2, count, robot.nv))
        ref_s = median_once(lambda: model.inverse_dynamics(qr, v, a))
        pin_model, pin_data = robot.model, robot.model.createData()
        loop_s = median_once(lambda: [pin.rnea(pin_model, pin_data, q[i], v[i], a[i]) for i in range(count)])
        rows.append(
            {
                "robot": name,
                "quantity": "tau (M, C, G with analytic dM/dq)",
                "reference_states_per_s": count / ref_s,
                "pinocchio_loop_states_per_s": count / loop_s,
                "pinocchio_over_reference": ref_s / loop_s,
            }
        )
    return rows


#: The issue's targets (#17): operations over M, C q̇ and G, as ``Equations.operation_count``.
SYMBOLIC_TARGETS = {
    "rp_arm": 20,
    "double_pendulum": 70,
    "rrp_arm": 120,
    "ur5": 760,
    "panda (7 arm joints)": 1700,
}


def bench_symbolic(quick: bool) -> list[dict]:
    from robodyn.equations.derive import derive_equations

    rrp = str(ROOT / "tests" / "data" / "rrp_arm.urdf")
    cases = (("rp_arm", None), ("double_pendulum", None), (rrp, None), ("ur5", None), ("panda", PANDA_ARM["lock"]))
    rows = []
    for name, lock in cases:
        start, cpu = time.perf_counter(), time.process_time()
        equations = derive_equations(name, lock=lock)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
        label = Path(name).stem + (" (7 arm joints)" if lock else "")
        operations = equations.operation_count()
        rows.append(
            {
                "robot": label,
                "form": equations.form,
                "derive_s": elapsed,
                "derive_cpu_s": cpu,
                "operations_M_Cv_G": operations,
                "target_operations": SYMBOLIC_TARGETS[label],
                "within_target": operations <= SYMBOLIC_TARGETS[label] and cpu < 5.0,
                "assignments": len(equations.assignments),
            }
        )
    return rows


def bench_codegen(quick: bool) -> list[dict]:
    import importlib.util
    import tempfile

    from robodyn.equations.derive import derive_equations, render

    rows = []
    for name, lock in (("ur5", None), ("panda", PANDA_ARM["lock"])):
        robot = robodyn.load(name, lock=lock)
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / f"{name}_dynamics.py"
            path.write_text(render(derive_equations(name, lock=lock), "python"))
            spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        rng = np.random.default_rng(3)
        q, v, a = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        model, data = robot.model, robot.model.createData()
        generated_s, raw_s, ratio = paired(
            lambda: module.inverse_dynamics(q, v, a), lambda: pin.rnea(model, data, q, v, a), repeats=7
        )
        count = 2_000 if quick else 20_000
        qs = robot.random_configuration(rng, count)
        vs, as_ = rng.normal(size=(2, count, robot.nv))
        batch_generated = median_once(lambda: module.inverse_dynamics(qs, vs, as_))
        batch_robodyn = median_once(lambda: robot.inverse_dynamics(qs, vs, as_))
        rows.append(
            {
                "robot": name + (" (7 arm joints)" if lock else ""),
                "generated_python_us": generated_s * 1e6,
                "pin_rnea_us": raw_s * 1e6,
                "single_ratio": ratio,
                "generated_numpy_batch_states_per_s": count / batch_generated,
                "robodyn_batch_states_per_s": count / batch_robodyn,
            }
        )
    return rows


def bench_simulation(quick: bool) -> list[dict]:
    duration = 2.0 if quick else 10.0
    rows = []
    for label, kwargs in (("panda (arm, fingers locked)", PANDA_ARM), ("panda (as loaded, mimic finger)", {})):
        robot = robodyn.load("panda", **kwargs)
        q0, v0 = robot.neutral_configuration(), np.zeros(robot.nv)
        for integrator in ("rk4", "semi-implicit-euler"):
            try:
                elapsed = median_once(
                    lambda integrator=integrator, robot=robot, q0=q0, v0=v0: simulate(
                        robot, q0, v0, duration, 1e-3, integrator=integrator
                    )
                )
                factor, note = duration / elapsed, ""
            except SimulationError as error:  # the passive fall whips the wrist: report where
                shorter = max(1.0, float(np.floor(error.time)) - 1.0)
                elapsed = median_once(
                    lambda integrator=integrator, robot=robot, q0=q0, v0=v0: simulate(
                        robot, q0, v0, shorter, 1e-3, integrator=integrator
                    )
                )
                factor = shorter / elapsed
                note = f"diverges at t = {error.time:.3g} s ({error.joint}); factor over the first {shorter:g} s"
            rows.append(
                {
                    "robot": label,
                    "integrator": integrator,
                    "duration_s": duration,
                    "dt_s": 1e-3,
                    "real_time_factor": factor,
                    "note": note,
                }
            )
        if robot.mimic is None:
            model, data = robot.model, robot.model.createData()

            def naive_rk4() -> None:
                q, v, h = q0.copy(), v0.copy(), 1e-3
                zero = np.zeros(robot.nv)
                for _ in range(int(duration / h)):
                    k1 = pin.aba(model, data, q, v, zero)
                    k2 = pin.aba(model, data, q + h / 2 * v, v + h / 2 * k1, zero)
                    k3 = pin.aba(model, data, q + h / 2 * (v + h / 2 * k1), v + h / 2 * k2, zero)
                    k4 = pin.aba(model, data, q + h * (v + h / 2 * k2), v + h * k3, zero)
                    q = q + h / 6 * (v + 2 * (v + h / 2 * k1) + 2 * (v + h / 2 * k2) + (v + h * k3))
                    v = v + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

            rows.append(
                {
                    "robot": label,
                    "integrator": "naive numpy RK4 over pin.aba (baseline)",
                    "duration_s": duration,
                    "dt_s": 1e-3,
                    "real_time_factor": duration / median_once(naive_rk4),
                }
            )
    return rows


def bench_recording(quick: bool) -> list[dict]:
    import tempfile

    from robodyn.viz.viewer import record

    duration = 2.0 if quick else 10.0
    robot = robodyn.load("panda")
    trajectory = simulate(robot, robot.neutral_configuration(), np.zeros(robot.nv), duration, 1e-3, integrator="rk4")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "panda.html"
        elapsed = median_once(lambda: record(robot, trajectory, path, fps=30))
        size = path.stat().st_size
    return [
        {
            "robot": "panda (as loaded)",
            "duration_s": duration,
            "fps": 30,
            "frames": int(duration * 30) + 1,
            "record_s": elapsed,
            "html_MB": size / 1e6,
        }
    ]


SECTIONS: dict[str, Callable[[bool], list[dict]]] = {
    "single": bench_single,
    "batch": bench_batch,
    "reference": bench_reference,
    "symbolic": bench_symbolic,
    "codegen": bench_codegen,
    "simulation": bench_simulation,
    "recording": bench_recording,
}


def _format(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1e4 else f"{value:,.0f}"
    return str(value)


def markdown(results: dict) -> str:
    lines = [f"# robodyn benchmarks ({results['date']}, {results['machine']})", ""]
    for section, rows in results["sections"].items():
        if not rows:
            continue
        lines += [f"## {section}", "", "| " + " | ".join(rows[0]) + " |", "|" + " --- |" * len(rows[0])]
        lines += ["| " + " | ".join(_format(row.get(key, "")) for key in rows[0]) + " |" for row in rows]
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes (a smoke run)")
    parser.add_argument("--only", nargs="*", choices=list(SECTIONS), help="run only these sections")
    parser.add_argument("--out", type=Path, default=OUT, help="output folder (default bench/)")
    arguments = parser.parse_args(argv)
    results = {
        "date": datetime.date.today().isoformat(),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, pin {pin.__version__}",
        "robodyn": robodyn.__version__,
        "quick": arguments.quick,
        "sections": {},
    }
    for name in arguments.only or SECTIONS:
        print(f"bench: {name}", file=sys.stderr)
        results["sections"][name] = SECTIONS[name](arguments.quick)
    arguments.out.mkdir(exist_ok=True)
    (arguments.out / "results.json").write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    text = markdown(results)
    (arguments.out / "results.md").write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
