"""The differential harness's cases: seeded robots, load options, states and batch sizes.

A :class:`Case` is a robot source (a file or URDF text) and the options it is loaded with
(gravity in any direction, ``lock=``, ``floating_base=``, ``threads=``), drawn from a seed:
the same seed gives the same case on every machine. Cases come from *generators*, one
entry each in :data:`GENERATORS` (name -> function of a seed): random kinematic trees
(``tests/random_robots.py``), random trees with fixed chains between moving joints, the
non-degenerate test robots of ``tests/conftest.py`` and the URDFs of ``urdf/`` and
``tests/data``. A new kind of robot (xacro, MJCF, joint friction and armature) is one more
generator; a new option is one more draw in :func:`draw_options`.

Every case carries its seed and a one-line reproduction (:meth:`Case.reproduction`).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import robodyn
import robodyn.reference
from tests.conftest import NONDEGENERATE_CASES, ROOT, URDF_FILES
from tests.random_robots import urdf_from_seed

#: Batch sizes that are not multiples of any chunk (the reference's 256, the CLI's rows)
#: or thread count (1, 2, 3, 4).
BATCH_SIZES = (1, 2, 3, 7, 129, 257, 1001)
#: The environment variable that replays one seed (``--differential-seed`` sets it too).
SEED_VARIABLE = "ROBODYN_DIFFERENTIAL_SEED"
#: Robots of the test data besides ``tests/data/robots`` (plain URDFs, no meshes).
DATA_FILES = sorted(path for path in (ROOT / "tests" / "data").glob("*.urdf"))


@dataclass(frozen=True)
class Case:
    """One robot and its load options, drawn from ``seed`` by ``generator``.

    Attributes:
        generator: The generator's name (:data:`GENERATORS`).
        seed: The seed it was drawn from.
        label: What the robot is (a file name, or the random tree's shape).
        source: A URDF path or URDF text.
        options: Keyword arguments of :func:`robodyn.load`.
    """

    generator: str
    seed: int
    label: str
    source: str | Path
    options: dict = field(default_factory=dict, hash=False, compare=False)

    @property
    def id(self) -> str:
        return f"{self.generator}-{self.seed}"

    def __str__(self) -> str:
        options = ", ".join(f"{key}={value!r}" for key, value in self.options.items())
        return f"{self.id} ({self.label}; {options or 'default options'})"

    def reproduction(self, test: str = "") -> str:
        """A shell line that runs the failing check on this case alone."""
        selection = f" -k '{test}'" if test else ""
        return f"{SEED_VARIABLE}={self.generator}:{self.seed} python -m pytest tests/differential{selection}"

    def robot(self) -> robodyn.Robot:
        return _load(self)

    def reference(self):
        """The reference model (no Pinocchio), with the same gravity, lock and base."""
        return _reference(self)

    @property
    def floating(self) -> bool:
        return bool(self.options.get("floating_base", False))

    @property
    def gravity(self) -> tuple[float, float, float]:
        return tuple(self.options.get("gravity", (0.0, 0.0, -9.81)))  # type: ignore[return-value]

    def text(self) -> str:
        return Path(self.source).read_text() if isinstance(self.source, Path) else str(self.source)


@functools.lru_cache(maxsize=64)
def _load(case: Case) -> robodyn.Robot:
    return robodyn.load(case.source, **case.options)


@functools.lru_cache(maxsize=64)
def _reference(case: Case):
    """The reference given every input ``robodyn.load`` got (but ``threads``: the reference has none)."""
    options = case.options
    return robodyn.reference.load(
        case.source, gravity=options.get("gravity"), lock=options.get("lock"), floating_base=case.floating,
        armature=options.get("armature"), xacro_args=options.get("xacro_args"), packages=options.get("packages"),
        check_inertia=options.get("check_inertia", True),
    )  # fmt: skip


# ----------------------------------------------------------------------------------------
# Options
# ----------------------------------------------------------------------------------------
def random_gravity(rng: np.random.Generator) -> tuple[float, float, float]:
    """Gravity in any direction, 3 to 15 m/s²."""
    direction = rng.normal(size=3)
    vector = direction / np.linalg.norm(direction) * rng.uniform(3.0, 15.0)
    return (float(vector[0]), float(vector[1]), float(vector[2]))


def lockable(text_or_path: str | Path) -> dict[str, tuple[float, float]]:
    """Moving joints that are no mimic and no mimic's source, with the range to lock them in."""
    try:
        spec = robodyn.reference.load(text_or_path).spec
    except robodyn.URDFError:  # no moving joint (a free body: MJCF contact files): nothing to lock
        return {}
    sources = {joint.mimic.joint for joint in spec.joints.values() if joint.mimic is not None}
    out = {}
    for joint in spec.joints.values():
        if joint.type == "fixed" or joint.mimic is not None or joint.name in sources:
            continue
        lower, upper = (-3.0, 3.0) if joint.type == "continuous" else (joint.lower, joint.upper)
        out[joint.name] = (float(max(lower, -3.0)), float(min(upper, 3.0)))  # an unlimited joint locks within ±3
    return out


def draw_options(rng: np.random.Generator, source: str | Path, *, floating: bool | None = None) -> dict:
    """Random load options: gravity (any direction), a lock at a non-zero position, a
    floating base, a thread count, a rotor's armature at one joint (each drawn or not)."""
    options: dict = {}
    if rng.random() < 0.7:
        options["gravity"] = random_gravity(rng)
    candidates = lockable(source)
    if len(candidates) > 1 and rng.random() < 0.35:
        name = sorted(candidates)[int(rng.integers(len(candidates)))]
        lower, upper = candidates[name]
        position = float(rng.uniform(0.1, 0.9) * (upper if rng.random() < 0.5 else lower))
        options["lock"] = {name: position if position != 0.0 else 0.5 * (lower + upper) or 0.05}  # non-zero, inside
    if floating if floating is not None else rng.random() < 0.3:
        options["floating_base"] = True
    else:
        options["floating_base"] = False
    options["threads"] = int(rng.integers(1, 4))
    free = sorted(set(candidates) - set(options.get("lock", {})))
    if free and rng.random() < 0.3:  # drawn last: the other options of a seed stay as they were
        options["armature"] = {free[int(rng.integers(len(free)))]: float(rng.uniform(0.01, 0.2))}
    return options


# ----------------------------------------------------------------------------------------
# Generators: name -> function of a seed giving a Case
# ----------------------------------------------------------------------------------------
#: The root link a floating random tree gets: a massless floating root with one moving
#: child has a singular mass matrix (the root's motion and the joint's are one motion).
BASE_LINK = (
    '<link name="link0"><inertial><origin xyz="0.01 -0.02 0.03" rpy="0.2 -0.1 0.3"/><mass value="2.5"/>'
    '<inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0015" izz="0.025"/></inertial></link>'
)


def with_base_mass(text: str, options: dict) -> str:
    """A random tree's text, its root given a mass when it floats."""
    return text.replace('<link name="link0"/>', BASE_LINK) if options.get("floating_base") else text


def random_tree(seed: int) -> Case:
    """A random tree (tests/random_robots.py) of 1 to 5 joints of random types."""
    rng = np.random.default_rng(seed)
    kinds = ["revolute", "continuous", "prismatic", "fixed"]
    types = [kinds[i] for i in rng.integers(0, 4, size=int(rng.integers(1, 4)))]
    if all(kind == "fixed" for kind in types):
        types[0] = "revolute"
    joints = int(rng.integers(1, 6))
    text = urdf_from_seed(seed, joints, types)
    options = draw_options(rng, text)
    return Case("random_tree", seed, f"{joints} joints of {'/'.join(types)}", with_base_mass(text, options), options)


def fixed_chain_tree(seed: int) -> Case:
    """A random tree with chains of fixed joints between moving ones."""
    rng = np.random.default_rng(seed)
    moving = ["revolute", "prismatic", "continuous"][int(rng.integers(3))]
    types = [moving, "fixed", "fixed", ["revolute", "prismatic"][int(rng.integers(2))]]
    joints = int(rng.integers(4, 7))
    text = urdf_from_seed(seed, joints, types)
    options = draw_options(rng, text)
    return Case("fixed_chain", seed, f"{joints} joints of {'/'.join(types)}", with_base_mass(text, options), options)


def nondegenerate_robot(seed: int) -> Case:
    """One of the non-degenerate test robots (mimic, oblique axes, locks), random gravity
    and threads on top of its own options."""
    rng = np.random.default_rng(seed)
    names = sorted(NONDEGENERATE_CASES)
    name = names[seed % len(names)]
    path, options = NONDEGENERATE_CASES[name]
    drawn = {"gravity": random_gravity(rng), "threads": int(rng.integers(1, 4)), "floating_base": False}
    return Case("test_robot", seed, name, path, {**drawn, **options})


def data_file(seed: int) -> Case:
    """A URDF of ``urdf/`` or ``tests/data`` with random options."""
    rng = np.random.default_rng(seed)
    files = [*URDF_FILES, *DATA_FILES, *sorted((ROOT / "tests" / "data" / "robots").glob("*.urdf"))]
    path = files[seed % len(files)]
    options = draw_options(rng, path)
    if options["floating_base"] and not _root_has_mass(path):  # a singular M (tests/differential/test_findings.py)
        options["floating_base"] = False
    return Case("data_file", seed, path.name, path, options)


def _root_has_mass(path: Path) -> bool:
    """Whether the root link of a URDF (the link no joint has as child) has a mass, read from the XML."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    children = {joint.find("child").get("link") for joint in root.iter("joint")}
    link = next(link for link in root.iter("link") if link.get("name") not in children)
    mass = link.find("inertial/mass")
    return mass is not None and float(mass.get("value", "0")) > 0


#: The xacro test arm and its package (a mimic joint, damping and friction in ``<dynamics>``).
XACRO_PACKAGE = ROOT / "tests" / "data" / "packages" / "robodyn_test_arm"
XACRO_ARM = XACRO_PACKAGE / "urdf" / "arm.urdf.xacro"
#: The MJCF test files (defaults classes, damping, frictionloss, armature; one floats).
MJCF_FILES = sorted((ROOT / "tests" / "data" / "mjcf").glob("*.xml"))


def xacro_arm(seed: int) -> Case:
    """The xacro test arm with drawn xacro arguments (a prefix on every name, the upper
    link's mass, the finger and its mimic joint or not) and its package map, then the
    usual options (gravity, a lock, armature; its root is massless: a fixed base)."""
    rng = np.random.default_rng(seed)
    xacro_args = {
        "prefix": ["", "left_", "r2_"][int(rng.integers(3))],
        "upper_mass": f"{rng.uniform(0.5, 3.0):.4f}",
        "finger": ["true", "false"][int(rng.integers(2))],
    }
    packages = {"robodyn_test_arm": str(XACRO_PACKAGE)}
    text = robodyn.reference.load(XACRO_ARM, xacro_args=xacro_args, packages=packages).urdf
    options = {**draw_options(rng, text, floating=False), "xacro_args": xacro_args, "packages": packages}
    label = f"arm.urdf.xacro ({', '.join(f'{k}:={v}' for k, v in xacro_args.items())})"
    return Case("xacro_arm", seed, label, XACRO_ARM, options)


def mjcf_file(seed: int) -> Case:
    """An MJCF test file, with the usual options (its own base: floating.xml floats)."""
    rng = np.random.default_rng(seed)
    path = MJCF_FILES[seed % len(MJCF_FILES)]
    floating = "<freejoint" in path.read_text() or 'type="free"' in path.read_text()
    text = robodyn.reference.load(path, floating_base=floating).urdf
    options = draw_options(rng, text, floating=floating)
    return Case("mjcf", seed, path.name, path, options)


#: Generators of sources the reference reads with options of its own (xacro arguments,
#: package maps, MJCF): tests/differential/test_sources.py.
SOURCE_GENERATORS: dict[str, Callable[[int], Case]] = {"xacro_arm": xacro_arm, "mjcf": mjcf_file}

#: Every generator of cases, by name. Add one entry per new kind of robot source.
GENERATORS: dict[str, Callable[[int], Case]] = {
    "random_tree": random_tree,
    "fixed_chain": fixed_chain_tree,
    "test_robot": nondegenerate_robot,
    "data_file": data_file,
}


def replayed() -> tuple[str, int] | None:
    """The ``generator:seed`` asked for by :data:`SEED_VARIABLE`, if any."""
    value = os.environ.get(SEED_VARIABLE)
    if not value:
        return None
    generator, _, seed = value.rpartition(":")
    return generator, int(seed)


def draw_cases(count_per_generator: int, *, base_seed: int, generators: tuple[str, ...] | None = None) -> list[Case]:
    """``count_per_generator`` cases of each generator (default :data:`GENERATORS`), seeds
    derived from ``base_seed`` (or only the replayed case, when :data:`SEED_VARIABLE` is set
    and names one of these generators)."""
    table = {**GENERATORS, **SOURCE_GENERATORS}
    names = generators or tuple(GENERATORS)
    replay = replayed()
    if replay is not None:
        return [table[replay[0]](replay[1])] if replay[0] in names else []
    return [table[name](base_seed + 1000 * index + k) for index, name in enumerate(names) for k in range(count_per_generator)]


def random_state_batch(robot, rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` random states; a floating base's poses get tilted, yawed orientations."""
    q = robot.random_configuration(rng, count)
    if robot.floating_base:
        for row in range(count):
            q[row] = robot.floating_configuration(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3), q[row, 7:])
    return q, rng.normal(size=(count, robot.nv)), rng.normal(size=(count, robot.nv))
