"""The paths that must agree, one entry each in :data:`PAIRS`.

A :class:`Pair` names two (or more) ways of computing the same numbers and checks them
on a :class:`~tests.differential.cases.Case` with a seeded generator; ``applies`` says
which cases it can run on (a compiled engine only takes fixed bases, ...). A new path
(CasADi or JAX export, derivatives, compiled controllers) is one more entry here.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import robodyn
from robodyn.dynamics.regressor import body_links
from robodyn.reference import numeric
from robodyn.reference.regressor import reference_body_links, reference_regressor
from tests.differential.agree import agree, same, scale
from tests.differential.cases import BATCH_SIZES, Case, random_state_batch


@dataclass(frozen=True)
class Pair:
    """Paths that must agree.

    Attributes:
        name: Short id (used in test ids and ``-k``).
        check: ``check(case, rng)`` raises :class:`~tests.differential.agree.PathsDisagreeError`.
        applies: Whether the pair runs on a case.
    """

    name: str
    check: Callable[[Case, np.random.Generator], None]
    applies: Callable[[Case], bool] = lambda case: True
    #: In the fast tier, only this many cases (the robots with the fewest degrees of
    #: freedom): for pairs that derive equations or compile C (seconds a case).
    fast_cases: int | None = None
    #: Cases with more degrees of freedom are left out (symbolic derivations grow fast).
    max_dof: int | None = None
    #: In the slow sweep, only this many cases (the first drawn that fit ``max_dof``).
    slow_cases: int | None = None


# ----------------------------------------------------------------------------------------
# Joint order: the reference orders joints depth first, the Robot its own way
# ----------------------------------------------------------------------------------------
class Order:
    """Maps states and results between the robot's coordinates and the reference's (joints
    matched by name; a floating base's 7 / 6 base coordinates first in both)."""

    def __init__(self, robot, reference) -> None:
        base_q, base_v = (7, 6) if robot.floating_base else (0, 0)
        joints = list(robot.joint_names[1:] if robot.floating_base else robot.joint_names)
        theirs = list(reference.joint_names[1:] if robot.floating_base else reference.joint_names)
        assert sorted(joints) == sorted(theirs), (joints, theirs)
        self.v = np.array(list(range(base_v)) + [base_v + theirs.index(name) for name in joints], dtype=int)
        self.q = np.array(list(range(base_q)) + [base_q + theirs.index(name) for name in joints], dtype=int)

    def to_reference(self, x: np.ndarray, kind: str = "v") -> np.ndarray:
        order = self.q if kind == "q" else self.v
        out = np.empty_like(x)
        out[..., order] = x
        return out

    def vector(self, x: np.ndarray) -> np.ndarray:
        return x[..., self.v]

    def matrix(self, x: np.ndarray) -> np.ndarray:
        return x[..., self.v, :][..., :, self.v]


# ----------------------------------------------------------------------------------------
# Robot (Pinocchio) against the reference
# ----------------------------------------------------------------------------------------
def robot_vs_reference(case: Case, rng: np.random.Generator) -> None:
    """τ, M, C v, C (fixed base), G, T, U, forward dynamics and the regressor."""
    robot, reference = case.robot(), case.reference()
    locked = set(case.options.get("lock") or {})
    same(case, "locked joints left moving", sorted(locked & set(robot.joint_names)), [], test="robot_vs_reference")
    order = Order(robot, reference)
    q, v, a = random_state_batch(robot, rng, 5)
    qr, vr, ar = order.to_reference(q, "q"), order.to_reference(v), order.to_reference(a)
    test = "robot_vs_reference"
    tau = robot.inverse_dynamics(q, v, a)
    mass = robot.mass_matrix(q)
    speed = scale(v)
    agree(case, "tau", tau, order.vector(reference.inverse_dynamics(qr, vr, ar)), test=test)
    agree(case, "M", mass, order.matrix(reference.mass_matrix(qr)), test=test)
    agree(case, "G", robot.gravity(q), order.vector(reference.gravity(qr)), floor=scale(tau), test=test)
    cv = robot.nonlinear_effects(q, v) - robot.gravity(q)
    agree(case, "C v", cv, order.vector(reference.coriolis_forces(qr, vr)), floor=scale(mass) * speed**2, test=test)
    if not robot.floating_base:
        coriolis = robot.coriolis_matrix(q, v)
        agree(case, "C", coriolis, order.matrix(reference.coriolis_matrix(qr, vr)), floor=scale(mass) * speed, test=test)
    kinetic = robot.kinetic_energy(q, v)
    agree(case, "T", kinetic, reference.kinetic_energy(qr, vr), test=test)
    agree(case, "U", robot.potential_energy(q), reference.potential_energy(qr), floor=scale(kinetic) + 1.0, test=test)
    torque = rng.normal(size=tau.shape) * (1.0 + scale(tau))
    accel = robot.forward_dynamics(q, v, torque)
    condition = max(float(np.linalg.cond(m)) for m in mass)
    agree(
        case, "forward dynamics", accel, order.vector(reference.forward_dynamics(qr, vr, order.to_reference(torque))),
        rtol=max(1e-9, 1e-14 * condition), test=test,
    )  # fmt: skip
    links = body_links(robot)
    theirs = reference_body_links(reference)
    same(case, "regressor bodies", sorted(links), sorted(theirs), test=test)
    columns = np.concatenate([10 * theirs.index(link) + np.arange(10) for link in links])
    y_reference = reference_regressor(reference, qr[:2], vr[:2], ar[:2])[:, order.v][:, :, columns]
    agree(case, "regressor", robot.regressor(q[:2], v[:2], a[:2]), y_reference, rtol=1e-8, test=test)


# ----------------------------------------------------------------------------------------
# One state, a batch, a batch in chunks, other thread counts
# ----------------------------------------------------------------------------------------
def _batch_size(rng: np.random.Generator) -> int:
    return int(rng.choice(BATCH_SIZES))


def _rows_to_check(count: int, rng: np.random.Generator) -> list[int]:
    """The first and last rows, rows at the chunk and thread boundaries, and a few others."""
    boundaries = {0, count - 1, 1, 2, 3, 127, 128, 129, 255, 256, 257, 1000}
    rows = sorted({row for row in boundaries if row < count} | set(rng.integers(0, count, size=min(count, 4)).tolist()))
    return rows


BATCH_QUANTITIES: dict[str, Callable] = {
    "tau": lambda m, q, v, a: m.inverse_dynamics(q, v, a),
    "M": lambda m, q, v, a: m.mass_matrix(q),
    "G": lambda m, q, v, a: m.gravity(q),
    "nle": lambda m, q, v, a: m.nonlinear_effects(q, v),
    "fd": lambda m, q, v, a: m.forward_dynamics(q, v, a),
    "T": lambda m, q, v, a: m.kinetic_energy(q, v),
    "U": lambda m, q, v, a: m.potential_energy(q),
}


def _single_batch_chunks(case: Case, model, q, v, a, rng, label: str, quantities: dict[str, Callable]) -> None:
    test = f"batch_{label}"
    count = len(q)
    split = int(rng.integers(1, count)) if count > 1 else 1
    rows = _rows_to_check(count, rng)
    for name, quantity in quantities.items():
        batch = np.asarray(quantity(model, q, v, a))
        same(case, f"{label} {name} batch rows", len(batch), count, test=test)
        single = np.array([quantity(model, q[i], v[i], a[i]) for i in rows])
        agree(case, f"{label} {name}: batch of {count} rows {rows} vs one state", batch[rows], single, rtol=1e-12, test=test)
        if count > 1:
            chunks = np.concatenate(
                [quantity(model, q[:split], v[:split], a[:split]), quantity(model, q[split:], v[split:], a[split:])]
            )
            agree(case, f"{label} {name}: batch of {count} vs split at {split}", batch, chunks, rtol=1e-12, test=test)


def robot_batches(case: Case, rng: np.random.Generator) -> None:
    """The Robot on one state, a batch of a size that is no multiple of a thread count, the
    batch split in two, and the robot loaded with one thread."""
    robot = case.robot()
    count = _batch_size(rng)
    q, v, a = random_state_batch(robot, rng, count)
    _single_batch_chunks(case, robot, q, v, a, rng, "robot", BATCH_QUANTITIES)
    if not robot.floating_base:
        _single_batch_chunks(case, robot, q, v, a, rng, "robot", {"C": lambda m, q, v, a: m.coriolis_matrix(q, v)})
    other = robodyn.load(case.source, **{**case.options, "threads": 1 if robot.threads != 1 else 3})
    for name, quantity in BATCH_QUANTITIES.items():
        agree(case, f"{name}: threads={robot.threads} vs threads={other.threads}", quantity(robot, q, v, a), quantity(other, q, v, a),
              rtol=1e-12, test="batch_robot")  # fmt: skip
    rows = _rows_to_check(count, rng)[:3]
    y = robot.regressor(q[rows], v[rows], a[rows])
    agree(case, "regressor batch vs one state", y, np.array([robot.regressor(q[i], v[i], a[i]) for i in rows]), rtol=1e-12)


@contextlib.contextmanager
def _reference_chunk(size: int):
    previous = numeric.CHUNK
    numeric.CHUNK = size
    try:
        yield
    finally:
        numeric.CHUNK = previous


def reference_batches(case: Case, rng: np.random.Generator) -> None:
    """The reference on one state, a batch, the batch split in two, and in chunks of 3."""
    reference = case.reference()
    robot = case.robot()
    order = Order(robot, reference)
    count = _batch_size(rng)
    q, v, a = random_state_batch(robot, rng, count)
    q, v, a = order.to_reference(q, "q"), order.to_reference(v), order.to_reference(a)
    quantities = {key: BATCH_QUANTITIES[key] for key in ("tau", "M", "G", "T", "U")}
    _single_batch_chunks(case, reference, q, v, a, rng, "reference", quantities)
    small = q[: min(count, 8)], v[: min(count, 8)], a[: min(count, 8)]
    whole = {name: quantity(reference, *small) for name, quantity in quantities.items()}
    with _reference_chunk(3):
        for name, quantity in quantities.items():
            agree(case, f"reference {name}: chunks of 3 vs one chunk", quantity(reference, *small), whole[name], rtol=1e-12,
                  test="batch_reference")  # fmt: skip


#: Every pair of paths the harness crosses, by name. Add one entry per new path.
PAIRS: dict[str, Pair] = {
    "robot_vs_reference": Pair("robot_vs_reference", robot_vs_reference),
    "batch_robot": Pair("batch_robot", robot_batches),
    "batch_reference": Pair("batch_reference", reference_batches),
}


# ----------------------------------------------------------------------------------------
# The compiled engine (robodyn.compile): against the Robot, in batches, asked twice
# ----------------------------------------------------------------------------------------
_COMPILED: dict[tuple, object] = {}


def compiled_of(robot, threads: int):
    """``robodyn.compile(robot)`` in the session's test cache (kept: compiling costs seconds)."""
    from robodyn.compiled import compile
    from tests.compiled_helpers import shared_cache

    key = (robot.urdf, tuple(robot.gravity_vector), threads)
    if key not in _COMPILED:
        with shared_cache():
            _COMPILED[key] = compile(robot, threads=threads)
    return _COMPILED[key]


def fixed_base(case: Case) -> bool:
    return not case.floating


COMPILED_QUANTITIES = {key: BATCH_QUANTITIES[key] for key in ("tau", "M", "G", "nle", "fd")}


def compiled_vs_robot(case: Case, rng: np.random.Generator) -> None:
    """Compiled τ, M, G, C v + G, forward dynamics against the Robot's; one state, a batch
    (no multiple of the thread count), the batch split in two."""
    robot = case.robot()
    compiled = compiled_of(robot, robot.threads)
    count = _batch_size(rng)
    q, v, a = random_state_batch(robot, rng, count)
    for name, quantity in COMPILED_QUANTITIES.items():
        ours, theirs = quantity(compiled, q, v, a), quantity(robot, q, v, a)
        tolerance = 1e-11
        if name == "fd":
            tolerance = max(1e-11, 64 * np.finfo(float).eps * max(np.linalg.cond(m) for m in robot.mass_matrix(q)))
        agree(case, f"compiled {name} vs Robot", ours, theirs, rtol=tolerance, test="compiled_vs_robot")
    _single_batch_chunks(case, compiled, q, v, a, rng, "compiled", COMPILED_QUANTITIES)


def _heavier(text: str, rng: np.random.Generator) -> tuple[str, str]:
    """The URDF with one moving link's mass and inertia scaled by 1.5 to 3."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(text)
    children = {joint.find("child").get("link") for joint in root.iter("joint") if joint.get("type") != "fixed"}
    links = [link for link in root.iter("link") if link.get("name") in children and link.find("inertial") is not None]
    link = links[int(rng.integers(len(links)))]
    factor = float(rng.uniform(1.5, 3.0))
    inertial = link.find("inertial")
    mass = inertial.find("mass")
    mass.set("value", repr(float(mass.get("value")) * factor))
    inertia = inertial.find("inertia")
    for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        inertia.set(key, repr(float(inertia.get(key, "0")) * factor))
    return ET.tostring(root, encoding="unicode"), f"mass of {link.get('name')} x{factor:.3f}"


def changed_case(case: Case, rng: np.random.Generator, what: str) -> tuple[Case, str]:
    """The case with one input changed: ``"gravity"``, ``"lock"`` or ``"mass"`` (a link's)."""
    from tests.differential.cases import lockable, random_gravity

    options = dict(case.options)
    if what == "gravity":
        options["gravity"] = random_gravity(rng)
        return Case(case.generator, case.seed, case.label + " (other gravity)", case.source, options), "gravity"
    if what == "lock":
        candidates = lockable(case.source)
        name = sorted(candidates)[int(rng.integers(len(candidates)))]
        lower, upper = candidates[name]
        current = dict(options.get("lock") or {})
        current[name] = float(rng.uniform(0.2, 0.8) * (upper if current.get(name, 0.0) <= 0 else lower))
        options["lock"] = current
        return Case(case.generator, case.seed, case.label + f" (lock {name})", case.source, options), f"lock {name}"
    text, label = _heavier(case.text(), rng)
    return Case(case.generator, case.seed, case.label + f" ({label})", text, options), label


def compile_twice(case: Case, rng: np.random.Generator) -> None:
    """``compile`` asked for a robot, then for the robot with one input changed (gravity,
    then a link's mass or a lock), returns the changed robot's numbers: a cache never
    answers for another input."""
    from tests.differential.cases import lockable

    robot = case.robot()
    first = compiled_of(robot, robot.threads)
    second_change = "lock" if len(lockable(case.source)) > 1 and rng.random() < 0.5 else "mass"
    for change in ("gravity", second_change):
        other_case, what = changed_case(case, rng, change)
        other = other_case.robot()
        second = compiled_of(other, other.threads)
        q, v, a = random_state_batch(other, rng, 3)
        for name, quantity in COMPILED_QUANTITIES.items():
            agree(other_case, f"compiled {name} after changing {what}", quantity(second, q, v, a), quantity(other, q, v, a),
                  rtol=1e-9, test="compile_twice")  # fmt: skip
        if robot.nv == other.nv:  # the negative control: the change shows in the numbers
            assert scale(first.gravity(q) - second.gravity(q)) > 0 or what.startswith("lock")


# ----------------------------------------------------------------------------------------
# Generated code (robodyn equations --symbolic --format python / c) and symbolic kinematics
# ----------------------------------------------------------------------------------------
def _equations(case: Case):
    from robodyn.equations.derive import derive_equations

    return derive_equations(case.source, form="compact", lock=case.options.get("lock"), gravity=case.options.get("gravity"))


def _in_order(names: list[str], robot) -> np.ndarray:
    return np.array([list(names).index(joint) for joint in robot.joint_names], dtype=int)


def generated_python_vs_robot(case: Case, rng: np.random.Generator) -> None:
    from robodyn.equations.derive import render

    robot = _stated_robot(case)  # the generated code states what the file states (no armature=)
    namespace: dict = {}
    exec(render(_equations(case), "python"), namespace)
    order = _in_order(namespace["JOINT_NAMES"], robot)
    q, v, a = random_state_batch(robot, rng, 4)
    qg, vg, ag = (np.empty_like(x) for x in (q, v, a))
    qg[:, order], vg[:, order], ag[:, order] = q, v, a
    test = "generated_python"
    tau = robot.inverse_dynamics(q, v, a)
    agree(case, "generated python tau", namespace["inverse_dynamics"](qg, vg, ag)[:, order], tau, test=test)
    agree(case, "generated python M", namespace["mass_matrix"](qg)[:, order][:, :, order], robot.mass_matrix(q), test=test)
    agree(case, "generated python G", namespace["gravity"](qg)[:, order], robot.gravity(q), floor=scale(tau), test=test)
    coriolis = namespace["coriolis_matrix"](qg, vg)[:, order][:, :, order]
    agree(case, "generated python C", coriolis, robot.coriolis_matrix(q, v), floor=scale(tau), test=test)


def _c_library(source: str, folder):
    import ctypes
    import subprocess

    path, library = folder / "generated.c", folder / "libgenerated.so"
    path.write_text(source)
    subprocess.run(["cc", "-std=c99", "-O1", "-shared", "-fPIC", str(path), "-o", str(library), "-lm"], check=True)
    return ctypes.CDLL(str(library))


def generated_c_vs_robot(case: Case, rng: np.random.Generator) -> None:
    import ctypes
    import tempfile
    from pathlib import Path

    from robodyn.equations.derive import render

    robot = _stated_robot(case)  # as for the generated Python
    equations = _equations(case)
    with tempfile.TemporaryDirectory() as folder:
        lib = _c_library(render(equations, "c"), Path(folder))
        order = _in_order(equations.joint_names, robot)
        n = robot.nv
        pointer = ctypes.POINTER(ctypes.c_double)
        for q, v, a in zip(*random_state_batch(robot, rng, 3), strict=True):
            qg, vg, ag = (np.empty(n) for _ in range(3))
            qg[order], vg[order], ag[order] = q, v, a
            tau, mass, gravity = np.zeros(n), np.zeros(n * n), np.zeros(n)
            lib.inverse_dynamics(*(x.ctypes.data_as(pointer) for x in (qg, vg, ag, tau)))
            lib.mass_matrix(qg.ctypes.data_as(pointer), mass.ctypes.data_as(pointer))
            lib.gravity(qg.ctypes.data_as(pointer), gravity.ctypes.data_as(pointer))
            expected = robot.inverse_dynamics(q, v, a)
            agree(case, "generated C tau", tau[order], expected, test="generated_c")
            agree(case, "generated C M", mass.reshape(n, n)[np.ix_(order, order)], robot.mass_matrix(q), test="generated_c")
            agree(case, "generated C G", gravity[order], robot.gravity(q), floor=scale(expected), test="generated_c")


def _frame(case: Case, rng: np.random.Generator) -> str:
    """A link moved by a joint, preferring one hanging from a chain of fixed joints."""
    spec = case.robot().spec
    joints = list(spec.joints.values())
    behind_fixed = [joint.child for joint in joints if joint.type == "fixed" and joint.parent != spec.root]
    moving = [joint.child for joint in joints if joint.type != "fixed"]
    candidates = behind_fixed or moving
    return sorted(candidates)[int(rng.integers(len(candidates)))]


def symbolic_kinematics_vs_frames(case: Case, rng: np.random.Generator) -> None:
    from robodyn.equations.kinematics import derive_kinematics, render_kinematics

    robot = case.robot()
    frame = _frame(case, rng)
    kinematics = derive_kinematics(case.source, frame, lock=case.options.get("lock"))
    namespace: dict = {}
    exec(render_kinematics(kinematics, "python"), namespace)
    order = _in_order(kinematics.joint_names, robot)
    q, _, _ = random_state_batch(robot, rng, 4)
    qg = np.empty_like(q)
    qg[:, order] = q
    test = "symbolic_kinematics"
    agree(
        case,
        f"symbolic position of {frame}",
        namespace["frame_position"](qg),
        robot.frame_position(q, frame),
        floor=1.0,
        test=test,
    )
    jacobian = np.asarray(namespace["frame_jacobian"](qg))[:, :, order]
    agree(case, f"symbolic Jacobian of {frame}", jacobian, robot.frame_jacobian(q, frame), floor=1.0, test=test)


# ----------------------------------------------------------------------------------------
# Simulation: both integrators, both engines, against each other and the energy law
# ----------------------------------------------------------------------------------------
def _energy(robot, trajectory) -> np.ndarray:
    return robot.kinetic_energy(trajectory.q, trajectory.v) + robot.potential_energy(trajectory.q)


def _initial(robot, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    q, v, _ = random_state_batch(robot, rng, 1)
    return q[0], 0.5 * v[0]


def simulation_energy(case: Case, rng: np.random.Generator) -> None:
    """A passive rigid-body run conserves T + U: RK4 to 1e-6 of the energy's swing,
    semi-implicit Euler to 1e-2; the two integrators agree to O(dt); with the joints'
    damping and friction acting (a file's ``<dynamics>``), T + U never grows."""
    robot = case.robot()
    q0, v0 = _initial(robot, rng)
    runs = {
        integrator: robodyn.simulate(robot, q0, v0, 0.1, 5e-4, integrator=integrator, limits="ignore", joint_friction=False)
        for integrator in ("rk4", "semi-implicit-euler")
    }
    size = (
        scale(robot.kinetic_energy(runs["rk4"].q, runs["rk4"].v))
        + scale(robot.potential_energy(runs["rk4"].q) - robot.potential_energy(q0))
        + 1e-3
    )
    for integrator, tolerance in (("rk4", 1e-6), ("semi-implicit-euler", 2e-2)):
        energy = _energy(robot, runs[integrator])
        agree(
            case,
            f"{integrator} energy drift",
            energy - energy[0],
            np.zeros_like(energy),
            rtol=tolerance,
            floor=size,
            test="simulation",
        )
    agree(case, "rk4 vs semi-implicit Euler v", runs["semi-implicit-euler"].v, runs["rk4"].v, rtol=0.05,
          floor=scale(runs["rk4"].v) + 1e-3, test="simulation")  # fmt: skip
    if robot.joint_damping.any() or robot.joint_friction.any():
        damped = _energy(robot, robodyn.simulate(robot, q0, v0, 0.1, 5e-4, limits="ignore"))
        agree(case, "energy growth under joint friction", np.maximum(np.diff(damped), 0.0), np.zeros(damped.size - 1),
              rtol=1e-6, floor=size, test="simulation")  # fmt: skip
    run = runs["rk4"]  # the samples are the dynamics': a = forward dynamics at the sample
    agree(
        case,
        "simulated a vs forward dynamics",
        run.a,
        robot.forward_dynamics(run.q, run.v, run.tau),
        rtol=1e-9,
        test="simulation",
    )


def engines_agree(case: Case, rng: np.random.Generator) -> None:
    """The compiled engine's run is the Pinocchio engine's, for both integrators."""
    robot = case.robot()
    compiled_of(robot, robot.threads)  # built in the test cache
    from tests.compiled_helpers import shared_cache

    q0, v0 = _initial(robot, rng)
    for integrator in ("rk4", "semi-implicit-euler"):
        python = robodyn.simulate(robot, q0, v0, 0.05, 1e-3, integrator=integrator, limits="ignore")
        with shared_cache():
            native = robodyn.simulate(robot, q0, v0, 0.05, 1e-3, integrator=integrator, limits="ignore", engine="compiled")
        for kind in ("q", "v", "a", "tau"):
            agree(case, f"{integrator} {kind}: compiled vs pinocchio engine", getattr(native, kind), getattr(python, kind),
                  rtol=1e-8, floor=1e-6, test="engines")  # fmt: skip


# ----------------------------------------------------------------------------------------
# Files: trajectory round trips and what the CLI writes
# ----------------------------------------------------------------------------------------
def _trajectory(robot, rng: np.random.Generator, count: int):
    q, v, a = random_state_batch(robot, rng, count)
    t = np.cumsum(rng.uniform(1e-3, 2e-2, count))
    return robodyn.Trajectory(t, q, v, a, robot.inverse_dynamics(q, v, a), list(robot.joint_names), robot.name)


def expected_header(robot, kinds=("q", "v", "a", "tau")) -> list[str]:
    """Column names from the robot's own naming (configuration_names, dofs)."""
    header = ["t"]
    for kind in kinds:
        names = robot.configuration_names if kind == "q" else [dof.name for dof in robot.dofs]
        header += [f"{kind}[{name}]" for name in names]
    return header


def file_round_trips(case: Case, rng: np.random.Generator) -> None:
    """Save and load CSV and NPZ: the same columns (named from the robot) and values, bit for bit."""
    import tempfile
    from pathlib import Path

    robot = case.robot()
    trajectory = _trajectory(robot, rng, _batch_size(rng))
    same(case, "trajectory header", trajectory.header(), expected_header(robot), test="files")
    with tempfile.TemporaryDirectory() as folder:
        for suffix in (".csv", ".npz"):
            path = trajectory.save(Path(folder) / f"run{suffix}")
            back = robodyn.Trajectory.load(path)
            same(case, f"{suffix} header", back.header(), trajectory.header(), test="files")
            for kind in ("t", "q", "v", "a", "tau"):
                agree(case, f"{suffix} {kind} read back", getattr(back, kind), getattr(trajectory, kind), rtol=0.0, test="files")
            back.check(robot)


def _cli(arguments: list[str]) -> str:
    """Run the CLI in this process: its exit code and stderr, as one string (``"0"`` when
    it succeeded quietly)."""
    import contextlib as _contextlib
    import io

    from robodyn.cli.app import main

    stderr = io.StringIO()
    with _contextlib.redirect_stdout(io.StringIO()), _contextlib.redirect_stderr(stderr):
        code = main(arguments)
    return f"{code}" + (f": {stderr.getvalue().strip()}" if code else "")


def _stated_robot(case: Case):
    """The case's robot as its file and the CLI's flags state it: every option but
    ``armature=`` (no flag, and generated code takes the file's), for the CLI and generated-code pairs."""
    if not case.options.get("armature"):
        return case.robot()
    return robodyn.load(case.source, **{key: value for key, value in case.options.items() if key != "armature"})


def _model_arguments(case: Case, robot) -> list[str]:
    """The CLI's model arguments for the case: the robot's own URDF (locks applied) as text."""
    arguments = [robot.urdf, "--floating-base" if robot.floating_base else "--fixed-base"]
    gravity = robot.gravity_vector
    return [*arguments, "--gravity=" + ",".join(repr(float(g)) for g in gravity)]


def written_columns(path) -> dict[str, np.ndarray]:
    """A file's columns read without robodyn: name -> values (CSV: csv module; Parquet:
    pyarrow; NPZ: numpy, its named arrays split into ``kind[name]`` columns)."""
    import csv
    from pathlib import Path

    path = Path(path)
    if path.suffix == ".csv":
        rows = [row for row in csv.reader(path.read_text().splitlines()) if row and not row[0].startswith("#")]
        values = np.array(rows[1:], dtype=float)
        return {name: values[:, i] for i, name in enumerate(rows[0])}
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        table = pq.read_table(path)
        return {name: table.column(name).to_numpy() for name in table.column_names}
    out: dict[str, np.ndarray] = {}
    with np.load(path, allow_pickle=False) as data:
        q_names, v_names = list(data["q_names"]), list(data["v_names"])
        out["t"] = data["t"]
        for kind in data.files:
            if kind in ("q_names", "v_names", "joint_names", "robot", "t"):
                continue
            array = data[kind]
            if kind == "M":
                for i, j in zip(*np.triu_indices(len(v_names)), strict=True):
                    out[f"M[{v_names[i]},{v_names[j]}]"] = array[:, i, j]
                continue
            names = q_names if kind == "q" else v_names
            out.update({f"{kind}[{name}]": array[:, k] for k, name in enumerate(names)})
    return out


def cli_torques_columns(case: Case, rng: np.random.Generator) -> None:
    """``robodyn torques --out`` (CSV, NPZ, Parquet; chunks that do not divide the rows)
    writes tau, G and M columns named from the robot, equal to the Python values."""
    import tempfile
    from pathlib import Path

    robot = _stated_robot(case)
    count = int(rng.choice([7, 129]))
    trajectory = _trajectory(robot, rng, count)
    chunk = int(rng.choice([5, 6, 64, 100]))
    dofs = [dof.name for dof in robot.dofs]
    upper = list(zip(*np.triu_indices(robot.nv), strict=True))
    tau = robot.inverse_dynamics(trajectory.q, trajectory.v, trajectory.a)
    gravity, mass = robot.gravity(trajectory.q), robot.mass_matrix(trajectory.q)
    expected = {name: tau[:, k] for k, name in enumerate(f"tau[{d}]" for d in dofs)}
    expected |= {f"G[{d}]": gravity[:, k] for k, d in enumerate(dofs)}
    expected |= {f"M[{dofs[i]},{dofs[j]}]": mass[:, i, j] for i, j in upper}
    expected |= {f"q[{name}]": trajectory.q[:, k] for k, name in enumerate(robot.configuration_names)}
    test = "cli_torques"
    with tempfile.TemporaryDirectory() as folder:
        source = Path(trajectory.save(Path(folder) / "in.csv"))
        for suffix in (".csv", ".npz", ".parquet"):
            out = Path(folder) / f"out{suffix}"
            code = _cli(["torques", *_model_arguments(case, robot), str(source), "--out", str(out), "--gravity-torques",
                         "--mass-matrix", "--chunk-rows", str(chunk)])  # fmt: skip
            same(case, f"torques exit code ({suffix})", code, "0", test=test)
            columns = written_columns(out)
            same(case, f"torques {suffix} columns", sorted(set(expected) - set(columns)), [], test=test)
            if suffix != ".npz":
                same(case, f"torques {suffix} column order", list(columns), expected_header(robot) + [f"G[{d}]" for d in dofs]
                     + [f"M[{dofs[i]},{dofs[j]}]" for i, j in upper], test=test)  # fmt: skip
            for name, values in expected.items():
                agree(case, f"torques {suffix} {name} (chunks of {chunk} rows, {count} rows)", columns[name], values, rtol=1e-12,
                      floor=scale(tau), test=test)  # fmt: skip


def cli_simulate_columns(case: Case, rng: np.random.Generator) -> None:
    """``robodyn simulate --out`` writes the trajectory ``robodyn.simulate`` computes."""
    import tempfile
    from pathlib import Path

    robot = _stated_robot(case)
    q0, _ = _initial(robot, rng)
    integrator = ["rk4", "semi-implicit-euler"][int(rng.integers(2))]
    expected = robodyn.simulate(robot, q0, np.zeros(robot.nv), 0.02, 1e-3, integrator=integrator, limits="ignore")
    with tempfile.TemporaryDirectory() as folder:
        for suffix in (".csv", ".npz"):
            out = Path(folder) / f"run{suffix}"
            q_text = ",".join(repr(float(x)) for x in q0)
            code = _cli(["simulate", *_model_arguments(case, robot), f"--q0={q_text}", "--duration", "0.02", "--dt", "0.001",
                         "--integrator", integrator, "--limits", "ignore", "--out", str(out)])  # fmt: skip
            same(case, f"simulate exit code ({suffix})", code, "0", test="cli_simulate")
            back = robodyn.Trajectory.load(out)
            same(case, f"simulate {suffix} header", back.header(), expected_header(robot), test="cli_simulate")
            for kind in ("t", "q", "v", "a", "tau"):
                agree(case, f"simulate {suffix} {kind}", getattr(back, kind), getattr(expected, kind), rtol=1e-12, floor=1e-12,
                      test="cli_simulate")  # fmt: skip


def cli_equations_json(case: Case, rng: np.random.Generator) -> None:
    """``robodyn equations --json`` at a state prints the Robot's τ, M, C, G."""
    import contextlib as _contextlib
    import io
    import json

    from robodyn.cli.app import main

    robot = _stated_robot(case)
    q, v, a = (x[0] for x in random_state_batch(robot, rng, 1))
    stdout = io.StringIO()
    text = [f"--{name}={','.join(repr(float(x)) for x in value)}" for name, value in (("q", q), ("v", v), ("a", a))]
    with _contextlib.redirect_stdout(stdout), _contextlib.redirect_stderr(io.StringIO()):
        code = main(["equations", *_model_arguments(case, robot), *text, "--json"])
    same(case, "equations exit code", code, 0, test="cli_equations")
    printed = json.loads(stdout.getvalue())
    test = "cli_equations"
    same(case, "equations joint names", printed["joint_names"], list(robot.joint_names), test=test)
    tau = robot.inverse_dynamics(q, v, a)
    agree(case, "equations tau", printed["tau"], tau, rtol=1e-12, test=test)
    agree(case, "equations M", printed["M"], robot.mass_matrix(q), rtol=1e-12, test=test)
    agree(case, "equations G", printed["G"], robot.gravity(q), rtol=1e-12, floor=scale(tau), test=test)
    if "C" in printed and not robot.floating_base:
        agree(case, "equations C", printed["C"], robot.coriolis_matrix(q, v), rtol=1e-12, floor=scale(tau), test=test)


# ----------------------------------------------------------------------------------------
# Identification: noise-free data recover the truth
# ----------------------------------------------------------------------------------------
def identification_recovers(case: Case, rng: np.random.Generator) -> None:
    """Torques of a heavier 'true' robot, identified on the nominal one with the changed
    body (and maybe others) unknown: the identified base values are the truth's."""
    from robodyn.ident import base_parameters, identify

    nominal = case.robot()
    text, label = _heavier(nominal.urdf, rng)
    truth = robodyn.load(text, **{key: value for key, value in case.options.items() if key != "lock"})
    links = body_links(nominal)
    changed = [link for link in links if not np.allclose(
        truth.inertial_parameters()[10 * links.index(link):][:10], nominal.inertial_parameters()[10 * links.index(link):][:10])]  # fmt: skip
    others = [link for link in links if link not in changed]
    bodies = changed + [link for link in others if rng.random() < 0.5]
    q, v, a = random_state_batch(nominal, rng, 60)
    tau = truth.inverse_dynamics(q, v, a)
    base = base_parameters(nominal, bodies=bodies, seed=int(rng.integers(1000)))
    result = identify(nominal, robodyn.Trajectory(np.arange(60) * 0.01, q, v, a, tau, list(nominal.joint_names)), base=base)
    test = "identification"
    expected = base.to_base(truth.inertial_parameters()[base.columns])
    agree(case, f"identified base parameters ({label}; bodies {bodies})", result.values, expected, rtol=1e-7, test=test)
    agree(case, "identified model's torques", result.predict(q, v, a), tau, rtol=1e-8, test=test)


PAIRS.update(
    {
        "compiled_vs_robot": Pair("compiled_vs_robot", compiled_vs_robot, fixed_base, fast_cases=2, max_dof=4, slow_cases=10),
        "compile_twice": Pair("compile_twice", compile_twice, fixed_base, fast_cases=1, max_dof=3, slow_cases=5),
        "generated_python": Pair(
            "generated_python", generated_python_vs_robot, fixed_base, fast_cases=2, max_dof=4, slow_cases=8
        ),
        "generated_c": Pair("generated_c", generated_c_vs_robot, fixed_base, fast_cases=1, max_dof=4, slow_cases=5),
        "symbolic_kinematics": Pair(
            "symbolic_kinematics", symbolic_kinematics_vs_frames, fixed_base, fast_cases=2, max_dof=4, slow_cases=10
        ),
        "simulation": Pair("simulation", simulation_energy),
        "engines": Pair("engines", engines_agree, fixed_base, fast_cases=1, max_dof=4, slow_cases=8),
        "files": Pair("files", file_round_trips),
        "cli_torques": Pair("cli_torques", cli_torques_columns),
        "cli_simulate": Pair("cli_simulate", cli_simulate_columns),
        "cli_equations": Pair("cli_equations", cli_equations_json),
        "identification": Pair("identification", identification_recovers),
    }
)


# ----------------------------------------------------------------------------------------
# Derivatives (Robot vs central differences, compiled vs Robot) and CasADi export vs Robot
# ----------------------------------------------------------------------------------------
def _tangent_differences(robot, function, q, v, third, step: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Central differences of ``function(q, v, third)`` along ``integrate`` (q) and in v."""
    by_q, by_v = np.empty((robot.nv, robot.nv)), np.empty((robot.nv, robot.nv))
    for column in range(robot.nv):
        e = np.zeros(robot.nv)
        e[column] = step
        ahead, behind = robot.integrate(q, e), robot.integrate(q, -e)
        by_q[:, column] = (function(ahead, v, third) - function(behind, v, third)) / (2 * step)
        by_v[:, column] = (function(q, v + e, third) - function(q, v - e, third)) / (2 * step)
    return by_q, by_v


def derivatives_vs_differences(case: Case, rng: np.random.Generator) -> None:
    """Robot.*_derivatives against central differences of τ and q̈ (floating bases along
    ``integrate``), the identities ∂τ/∂a = M and ∂q̈/∂τ·M = I, and one state vs a batch."""
    robot = case.robot()
    q, v, a = (x[0] for x in random_state_batch(robot, rng, 1))
    test = "derivatives"
    dq, dv, mass = robot.inverse_dynamics_derivatives(q, v, a)
    by_q, by_v = _tangent_differences(robot, robot.inverse_dynamics, q, v, a)
    floor = max(scale(by_q), scale(by_v))
    agree(case, "dtau/dq vs central differences", dq, by_q, rtol=1e-6, floor=floor, test=test)
    agree(case, "dtau/dv vs central differences", dv, by_v, rtol=1e-6, floor=floor, test=test)
    agree(case, "dtau/da vs M", mass, robot.mass_matrix(q), rtol=1e-12, test=test)
    tau = robot.inverse_dynamics(q, v, a)
    fq, fv, inverse = robot.forward_dynamics_derivatives(q, v, tau)
    by_q, by_v = _tangent_differences(robot, robot.forward_dynamics, q, v, tau)
    condition = float(np.linalg.cond(mass))
    tolerance = max(1e-6, 1e-9 * condition)
    floor = max(scale(by_q), scale(by_v))
    agree(case, "dqdd/dq vs central differences", fq, by_q, rtol=tolerance, floor=floor, test=test)
    agree(case, "dqdd/dv vs central differences", fv, by_v, rtol=tolerance, floor=floor, test=test)
    agree(case, "dqdd/dtau M vs I", inverse @ mass, np.eye(robot.nv), rtol=max(1e-10, 1e-14 * condition), test=test)
    count = _batch_size(rng)
    qs, vs, accelerations = random_state_batch(robot, rng, count)
    batch = robot.inverse_dynamics_derivatives(qs, vs, accelerations)
    row = int(rng.integers(count))
    for name, stacked, single in zip(
        ("dq", "dv", "da"), batch, robot.inverse_dynamics_derivatives(qs[row], vs[row], accelerations[row]), strict=True
    ):
        agree(case, f"batch row {row} of {count} dtau/{name} vs one state", stacked[row], single, rtol=0.0, test=test)


def compiled_derivatives_vs_robot(case: Case, rng: np.random.Generator) -> None:
    """Compiled ∂τ and ∂q̈ (generated C) against the Robot's (Pinocchio's analytical
    derivatives), on a batch whose size is no multiple of the thread count."""
    robot = case.robot()
    compiled = compiled_of(robot, robot.threads)
    count = _batch_size(rng)
    q, v, a = random_state_batch(robot, rng, count)
    test = "compiled_derivatives"
    for label, ours, theirs in (
        ("dtau", compiled.inverse_dynamics_derivatives(q, v, a), robot.inverse_dynamics_derivatives(q, v, a)),
        ("dqdd", compiled.forward_dynamics_derivatives(q, v, a), robot.forward_dynamics_derivatives(q, v, a)),
    ):
        floor = max(scale(part) for part in theirs)
        for name, mine, reference in zip(("dq", "dv", "third"), ours, theirs, strict=True):
            agree(case, f"compiled {label}/{name} vs Robot", mine, reference, rtol=1e-9, floor=floor, test=test)


def casadi_vs_robot(case: Case, rng: np.random.Generator) -> None:
    """The exported CasADi functions against the Robot, and CasADi's own Jacobian of the
    inverse dynamics against Robot.inverse_dynamics_derivatives."""
    import casadi

    from robodyn.export import casadi_functions

    robot = case.robot()
    functions = casadi_functions(robot, frames=[])
    q, v, a = (x[0] for x in random_state_batch(robot, rng, 1))
    test = "casadi"
    tau = robot.inverse_dynamics(q, v, a)
    agree(case, "casadi tau", functions["inverse_dynamics"](q, v, a).full().ravel(), tau, rtol=1e-11, test=test)
    agree(case, "casadi M", functions["mass_matrix"](q).full(), robot.mass_matrix(q), rtol=1e-11, test=test)
    agree(case, "casadi G", functions["gravity"](q).full().ravel(), robot.gravity(q), rtol=1e-11, floor=scale(tau), test=test)
    fd = robot.forward_dynamics(q, v, tau)
    agree(case, "casadi FD", functions["forward_dynamics"](q, v, tau).full().ravel(), fd, rtol=1e-9, floor=scale(a), test=test)
    symbols = [casadi.SX.sym(name, robot.nv) for name in ("q", "v", "a")]
    jacobian = casadi.Function("j", symbols, [casadi.jacobian(functions["inverse_dynamics"](*symbols), s) for s in symbols])
    ours = [part.full() for part in jacobian(q, v, a)]
    theirs = robot.inverse_dynamics_derivatives(q, v, a)
    floor = max(scale(part) for part in theirs)
    for name, mine, reference in zip(("dq", "dv", "da"), ours, theirs, strict=True):
        agree(case, f"casadi jacobian dtau/{name} vs Robot", mine, reference, rtol=1e-10, floor=floor, test=test)


PAIRS.update(
    {
        "derivatives": Pair("derivatives", derivatives_vs_differences),
        "compiled_derivatives": Pair(
            "compiled_derivatives", compiled_derivatives_vs_robot, fixed_base, fast_cases=1, max_dof=4, slow_cases=6
        ),
        "casadi": Pair("casadi", casadi_vs_robot, fixed_base, fast_cases=1, max_dof=4, slow_cases=6),
    }
)
