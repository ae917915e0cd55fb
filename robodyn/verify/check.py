"""Verification: Pinocchio's dynamics against the independent Lagrangian reference.

:func:`check_robot` draws random states within the joint limits (seeded), evaluates
``tau``, ``M``, ``C v``, ``C`` and ``G`` with both implementations, matches joints by name,
and reports the largest absolute and relative errors. It also checks the passivity
property ``Ṁ − 2C`` skew-symmetric for both: for Pinocchio with ``Ṁ`` by central finite
differences of ``M`` along ``v`` (truncation and rounding error about 1e-9 relative, so
that check uses ``FINITE_DIFFERENCE_TOLERANCE``), for the reference with its analytic ``Ṁ``;
both relative to the larger of ``max |Ṁ|`` and ``max |M| max |v|``.

On the convention of ``C``: ``C`` is not unique (any ``C`` with ``C v`` fixed will do for
``tau``); the reference's is the Christoffel form ``C_ij = Σ_k Γ_ijk v_k``. Pinocchio's
``computeCoriolisMatrix`` coincides with it for robots whose joints are all one-degree-of-
freedom (revolute, continuous, prismatic): ``check`` compares the full matrices and the
whole zoo passes. (For multi-degree-of-freedom joints such as a spherical joint the two
may differ while both keep ``Ṁ − 2C`` skew.)
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from robodyn import reference
from robodyn.common.text import quoted
from robodyn.dynamics.loading import load
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.verify.constrained import DESCRIPTIONS as CONSTRAINT_DESCRIPTIONS
from robodyn.verify.constrained import constraint_values

#: ``progress(stage, done, total)``: called as the reference evaluates the samples.
Progress = Callable[[str, int, int], None]
#: Most progress reports a check makes (the samples are evaluated in as many slices).
PROGRESS_STEPS = 20

#: Default tolerance on the relative error of every compared quantity.
DEFAULT_TOLERANCE = 1e-9
#: Tolerance for Pinocchio's skew-symmetry check, whose Ṁ comes from finite differences.
FINITE_DIFFERENCE_TOLERANCE = 1e-6
QUANTITIES = ("tau", "M", "Cv", "C", "G")


@dataclass(frozen=True)
class Comparison:
    """Largest errors of one quantity over all samples.

    Attributes:
        max_abs: Largest absolute difference (SI units of the quantity).
        max_rel: ``max_abs`` divided by the largest magnitude of the reference's values, or
            by the term's natural size when that is larger (``max|M| max|v|`` for ``C``,
            ``max|M| max|v|²`` for ``C v``, ``max|tau|`` for ``G``), so that a term that
            vanishes is not compared with rounding noise.
        tolerance: Largest accepted ``max_rel``.
        where: The joint (vectors) or pair of joints (matrices) of the largest absolute
            difference, e.g. ``"joint 'elbow'"``; empty when there is nothing to compare.
    """

    max_abs: float
    max_rel: float
    tolerance: float
    where: str = ""

    @property
    def passed(self) -> bool:
        """Whether the relative error is within tolerance."""
        return bool(self.max_rel <= self.tolerance)


@dataclass(frozen=True)
class CheckReport:
    """Outcome of :func:`check_robot`.

    Attributes:
        robot: Robot name.
        samples: Number of random states.
        seed: Seed of the random states.
        joint_names: Joints compared (in Pinocchio's order).
        comparisons: Errors of ``tau``, ``M``, ``Cv``, ``C``, ``G`` (reference vs Pinocchio),
            and ``skew_pinocchio``, ``skew_reference`` (how far ``Ṁ − 2C`` is from skew).
    """

    robot: str
    samples: int
    seed: int
    joint_names: list[str]
    comparisons: dict[str, Comparison] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        """Whether every comparison is within tolerance."""
        return all(comparison.passed for comparison in self.comparisons.values())

    @property
    def failures(self) -> list[str]:
        """One line for each failed comparison: the quantity, its error and where it is largest."""
        return [
            f"{name}: relative error {comparison.max_rel:.3e} > {comparison.tolerance:.0e}"
            + (f" at {comparison.where}" if comparison.where else "")
            for name, comparison in self.comparisons.items()
            if not comparison.passed
        ]

    def to_dict(self) -> dict:
        """JSON-ready (the ``robodyn check --json`` output)."""
        return report_dict(self)

    def text(self) -> str:
        """A readable table: one line a quantity, then PASSED or FAILED with the failures."""
        return report_text(self)

    @property
    def worst_relative_error(self) -> float:
        """Largest relative error of the reference-vs-Pinocchio comparisons."""
        return max(self.comparisons[name].max_rel for name in QUANTITIES if name in self.comparisons)


def _largest(values: np.ndarray) -> float:
    return float(np.max(np.abs(values))) if values.size else 0.0


def _location(difference: np.ndarray, dof_names: list[str], matrix: bool) -> str:
    """Where a stack of differences is largest: a joint (vectors) or a pair of joints (matrices)."""
    if not difference.size:
        return ""
    index = np.unravel_index(int(np.argmax(np.abs(difference))), difference.shape)
    if matrix:
        return f"joints ({dof_names[index[-2]]!r}, {dof_names[index[-1]]!r})"
    return f"joint {dof_names[index[-1]]!r}"


def _compare(
    actual: np.ndarray, expected: np.ndarray, tolerance: float, floor: float = 0.0, dof_names: list[str] | None = None
) -> Comparison:
    """Errors relative to the larger of the expected values' magnitude and ``floor``."""
    difference = actual - expected
    max_abs = _largest(difference)
    scale = max(_largest(expected), floor)
    where = _location(difference, dof_names, difference.ndim == 3) if dof_names else ""
    return Comparison(max_abs, max_abs / scale if scale > 0 else max_abs, tolerance, where)


def skewness(matrices: np.ndarray, scale: float, tolerance: float, dof_names: list[str] | None = None) -> Comparison:
    """How far matrices are from skew-symmetric: largest ``|S + Sᵀ|``, relative to ``scale``.

    Args:
        matrices: Shape (n, n) or (N, n, n).
        scale: The size the symmetric part is compared with (e.g. ``max |Ṁ|``).
        tolerance: Largest accepted relative value.
        dof_names: Names of the ``n`` coordinates, to say where the worst entry is.
    """
    symmetric_part = matrices + np.swapaxes(matrices, -1, -2)
    max_abs = _largest(symmetric_part)
    where = _location(symmetric_part, dof_names, True) if dof_names else ""
    return Comparison(max_abs, max_abs / scale if scale > 0 else max_abs, tolerance, where)


def check_robot(
    source: str | os.PathLike | Robot,
    *,
    samples: int = 100,
    seed: int = 0,
    tolerance: float = DEFAULT_TOLERANCE,
    check_inertia: bool = True,
    reference_source: str | os.PathLike | None = None,
    constraints: object = None,
    progress: Progress | None = None,
) -> CheckReport:
    """Compare Pinocchio with the reference at random states within the joint limits.

    Args:
        source: Anything :func:`robodyn.load` takes, or a loaded ``Robot``. With a floating
            base ``tau``, ``M``, ``C v`` and ``G`` are compared (the reference's ``C`` is in
            its own coordinates there).
        reference_source: The model the reference is built from (anything
            :func:`robodyn.reference.load` takes); default the robot's own URDF. Given the
            true URDF, ``check`` tells whether a robot built some other way (edited, locked,
            loaded from another file) has the true dynamics.
        samples: Number of random states.
        seed: Seed of the random generator.
        tolerance: Largest accepted relative error.
        check_inertia: As for :func:`robodyn.load`.
        constraints: As for :func:`robodyn.load` (when ``source`` is not a robot). A robot
            with constraints (these, or its file's ``<equality>``) also has ``Φ``, ``J``,
            ``J̇ v`` and the constrained ``v̇`` and ``λ`` compared
            (:mod:`robodyn.verify.constrained`).
        progress: Called as ``progress("reference", done, samples)`` as the reference
            (the slow side: seconds a sample on a 60-joint robot) evaluates the states.

    Returns:
        The report; ``report.passed`` tells whether every error is within tolerance, and
        ``report.failures`` names each failed quantity and the joint where it is worst. When
        the two models do not have the same joints, the report has one failed comparison,
        ``joints``, naming them (``max_abs``: how many differ).

    Raises:
        InputError: For a robot with no moving mass (every term is zero: nothing to compare).
    """
    robot = source if isinstance(source, Robot) else load(source, check_inertia=check_inertia, constraints=constraints)
    _check_moving_mass(robot)
    model = reference.load(
        robot.urdf if reference_source is None else reference_source,
        gravity=tuple(robot.gravity_vector),
        check_inertia=check_inertia,
        floating_base=robot.floating_base,
        armature=dict(robot.options.armature),
    )
    report = CheckReport(robot.name, samples, seed, list(robot.joint_names))
    unmatched = _unmatched_joints(robot.joint_names, model.joint_names)
    if unmatched is not None:
        report.comparisons["joints"] = unmatched
        return report
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng, samples)
    v = rng.normal(size=(samples, robot.nv))
    a = rng.normal(size=(samples, robot.nv))
    matched = _Matched(robot, model)
    report.comparisons.update(_compare_dynamics(robot, matched, (q, v, a), tolerance, progress))
    if robot.constraints:
        tau = rng.normal(size=(samples, robot.nv))
        for name, (actual, expected, floor, names) in constraint_values(robot, matched, q, v, tau).items():
            report.comparisons[name] = _compare(actual, expected, tolerance, floor, names)
    return report


def _check_moving_mass(robot: Robot) -> None:
    """Refuse a robot none of whose moving bodies has mass or inertia (``M``, ``C``, ``G``
    and ``tau`` are zero in both models: a PASSED would say nothing)."""
    model = robot.model
    bodies = [model.inertias[i] for i in range(1, model.njoints)]  # fixed links are merged into their joint's body
    if robot.nv == 0 or all(body.mass <= 0 and not np.any(body.inertia) for body in bodies):
        raise InputError(
            "source",
            "a robot with some moving mass (with none every dynamic term is zero: there is nothing to compare)",
            f"{quoted(robot.name)}, whose {robot.nv} joints move no mass and no inertia",
        )


def _reference_terms(model, states: tuple[np.ndarray, ...], progress: Progress | None) -> dict[str, np.ndarray]:
    """The reference's terms at every state (one pass a slice of samples, progress after each)."""
    count = len(states[0])
    size = max(1, -(-count // PROGRESS_STEPS))
    slices = []
    for start in range(0, max(count, 1), size):  # one empty slice for no samples
        slices.append(model.terms(*(x[start : start + size] for x in states)))
        if progress:
            progress("reference", min(start + size, count), count)
    return {name: np.concatenate([part[name] for part in slices]) for name in slices[0]}


def _unmatched_joints(robot_joints: list[str], reference_joints: list[str]) -> Comparison | None:
    """A failed ``joints`` comparison naming the joints only one model has; ``None`` if none."""
    extra = [name for name in robot_joints if name not in reference_joints]
    missing = [name for name in reference_joints if name not in robot_joints]
    if not (extra or missing):
        return None
    where = ", ".join(
        [f"joint {name!r} only in the robot" for name in extra] + [f"joint {name!r} only in the reference" for name in missing]
    )
    return Comparison(float(len(extra) + len(missing)), float(len(extra) + len(missing)), 0.0, where)


class _Matched:
    """The reference model with its coordinates in the robot's order (joints matched by
    name; a floating base's 7 position and 6 velocity coordinates come first in both)."""

    def __init__(self, robot: Robot, model) -> None:
        self.model = model
        base_q, base_v = (7, 6) if robot.floating_base else (0, 0)
        joints = robot.joint_names[1:] if robot.floating_base else robot.joint_names
        reference_joints = model.joint_names[1:] if robot.floating_base else model.joint_names
        self.v_order = list(range(base_v)) + [base_v + reference_joints.index(name) for name in joints]
        self.q_order = list(range(base_q)) + [base_q + reference_joints.index(name) for name in joints]

    def to_reference(self, x: np.ndarray, order: list[int]) -> np.ndarray:
        """Samples (N, n) in the reference's order."""
        out = np.empty_like(x)
        out[:, order] = x
        return out

    def from_reference(self, x: np.ndarray) -> np.ndarray:
        """Vectors (N, nv) or matrices (N, nv, nv) of the reference in the robot's order."""
        return x[:, self.v_order] if x.ndim == 2 else x[:, self.v_order][:, :, self.v_order]

    def states(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q``, ``v``, ``a`` in the reference's order."""
        return self.to_reference(q, self.q_order), self.to_reference(v, self.v_order), self.to_reference(a, self.v_order)


def _compare_dynamics(
    robot: Robot, matched: _Matched, states: tuple[np.ndarray, ...], tolerance: float, progress: Progress | None = None
) -> dict[str, Comparison]:
    """``tau``, ``M``, ``C v``, ``G`` (and, on a fixed base, ``C`` and ``Ṁ − 2C`` skew) of
    both implementations at the states ``q`` (N, nq), ``v`` and ``a`` (N, nv)."""
    q, v, a = states
    from_reference = matched.from_reference
    every = {
        name: from_reference(value) for name, value in _reference_terms(matched.model, matched.states(q, v, a), progress).items()
    }
    reference_values = {name: every[name] for name in ("tau", "M", "Cv", "G")}
    coriolis = robot.coriolis_matrix(q, v)
    pinocchio_values = {
        "tau": robot.inverse_dynamics(q, v, a),
        "M": robot.mass_matrix(q),
        "Cv": np.einsum("nij,nj->ni", coriolis, v),
        "G": robot.gravity(q),
    }
    # A term that vanishes (C of a single joint, G of joints on vertical axes) is compared
    # relative to its natural size: M times speeds, or the torques of the same states.
    mass_scale, speed, torque_scale = _largest(reference_values["M"]), _largest(v), _largest(reference_values["tau"])
    floors = {"tau": 0.0, "M": 0.0, "Cv": mass_scale * speed**2, "C": mass_scale * speed, "G": torque_scale}
    dofs = [dof.name for dof in robot.dofs]
    comparisons = {
        name: _compare(pinocchio_values[name], reference_values[name], tolerance, floors[name], dofs) for name in reference_values
    }
    if robot.floating_base:  # C (and Ṁ − 2C) are in other coordinates there: τ, M, C v, G suffice
        return comparisons
    reference_c = every["C"]
    comparisons["C"] = _compare(coriolis, reference_c, tolerance, floors["C"], dofs)
    step = 1e-6
    m_dot = (robot.mass_matrix(q + step * v) - robot.mass_matrix(q - step * v)) / (2 * step)
    # Relative to the size of Ṁ, or of M times the speeds when Ṁ happens to be tiny
    # (the finite difference's rounding error scales with M, not with Ṁ).
    scale = max(_largest(m_dot), mass_scale * speed)
    comparisons["skew_pinocchio"] = skewness(m_dot - 2 * coriolis, scale, FINITE_DIFFERENCE_TOLERANCE, dofs)
    m_dot_reference = every["Mdot"]
    comparisons["skew_reference"] = skewness(m_dot_reference - 2 * reference_c, scale, tolerance, dofs)
    return comparisons


def report_dict(report: CheckReport) -> dict:
    """A JSON-ready form of a report.

    Args:
        report: The comparison's report.
    """
    return {
        "robot": report.robot,
        "samples": report.samples,
        "seed": report.seed,
        "joint_names": report.joint_names,
        "passed": report.passed,
        "comparisons": {
            name: {"max_abs": c.max_abs, "max_rel": c.max_rel, "tolerance": c.tolerance, "passed": c.passed, "where": c.where}
            for name, c in report.comparisons.items()
        },
    }


_DESCRIPTIONS = {
    "tau": "inverse dynamics tau = M a + C v + G",
    "M": "mass matrix M(q)",
    "Cv": "Coriolis forces C(q, v) v",
    "C": "Coriolis matrix C(q, v)",
    "G": "gravity G(q)",
    "skew_pinocchio": "Mdot - 2C skew (Pinocchio, Mdot by finite differences)",
    "skew_reference": "Mdot - 2C skew (reference, analytic Mdot)",
    "joints": "joint names of the robot and the reference",
    **CONSTRAINT_DESCRIPTIONS,
}


def report_text(report: CheckReport) -> str:
    """A readable table of a report.

    Args:
        report: The comparison's report.
    """
    lines = [
        f"check {report.robot}: Pinocchio vs the Lagrangian reference, {report.samples} random states (seed {report.seed}), "
        f"{len(report.joint_names)} joints",
        "",
        f"{'quantity':58s} {'max abs error':>14s} {'max rel error':>14s} {'tolerance':>10s}  result",
    ]
    for name, comparison in report.comparisons.items():
        lines.append(
            f"{_DESCRIPTIONS[name]:58s} {comparison.max_abs:14.3e} {comparison.max_rel:14.3e} {comparison.tolerance:10.0e}  "
            f"{'pass' if comparison.passed else 'FAIL'}"
        )
    lines += ["", "PASSED" if report.passed else "FAILED"]
    lines += [f"  {failure}" for failure in report.failures]
    return "\n".join(lines)
