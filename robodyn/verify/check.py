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
from dataclasses import dataclass, field

import numpy as np

from robodyn import reference
from robodyn.dynamics.loading import load
from robodyn.dynamics.robot import Robot

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
    """

    max_abs: float
    max_rel: float
    tolerance: float

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
    def worst_relative_error(self) -> float:
        """Largest relative error of the reference-vs-Pinocchio comparisons."""
        return max(self.comparisons[name].max_rel for name in QUANTITIES if name in self.comparisons)


def _largest(values: np.ndarray) -> float:
    return float(np.max(np.abs(values))) if values.size else 0.0


def _compare(actual: np.ndarray, expected: np.ndarray, tolerance: float, floor: float = 0.0) -> Comparison:
    """Errors relative to the larger of the expected values' magnitude and ``floor``."""
    max_abs = _largest(actual - expected)
    scale = max(_largest(expected), floor)
    return Comparison(max_abs, max_abs / scale if scale > 0 else max_abs, tolerance)


def _skewness(matrices: np.ndarray, scale: float, tolerance: float) -> Comparison:
    """How far matrices are from skew-symmetric: largest |S + Sᵀ|, relative to ``scale``."""
    symmetric_part = matrices + np.swapaxes(matrices, -1, -2)
    max_abs = float(np.max(np.abs(symmetric_part))) if matrices.size else 0.0
    return Comparison(max_abs, max_abs / scale if scale > 0 else max_abs, tolerance)


def check_robot(
    source: str | os.PathLike | Robot,
    *,
    samples: int = 100,
    seed: int = 0,
    tolerance: float = DEFAULT_TOLERANCE,
    check_inertia: bool = True,
) -> CheckReport:
    """Compare Pinocchio with the reference at random states within the joint limits.

    Args:
        source: Anything :func:`robodyn.load` takes, or a loaded ``Robot``. With a floating
            base ``tau``, ``M``, ``C v`` and ``G`` are compared (the reference's ``C`` is in
            its own coordinates there).
        samples: Number of random states.
        seed: Seed of the random generator.
        tolerance: Largest accepted relative error.
        check_inertia: As for :func:`robodyn.load`.

    Returns:
        The report; ``report.passed`` tells whether every error is within tolerance.
    """
    robot = source if isinstance(source, Robot) else load(source, check_inertia=check_inertia)
    model = reference.load(
        robot.urdf, gravity=robot.gravity_vector, check_inertia=check_inertia, floating_base=robot.floating_base
    )
    if sorted(model.joint_names) != sorted(robot.joint_names):
        raise AssertionError(f"joint sets differ: {robot.joint_names} vs {model.joint_names}")
    # Index of each of robot's coordinates in the reference's (joints matched by name; a
    # floating base's 7 position and 6 velocity coordinates come first in both).
    base_q, base_v = (7, 6) if robot.floating_base else (0, 0)
    joints = robot.joint_names[1:] if robot.floating_base else robot.joint_names
    reference_joints = model.joint_names[1:] if robot.floating_base else model.joint_names
    v_order = list(range(base_v)) + [base_v + reference_joints.index(name) for name in joints]
    q_order = list(range(base_q)) + [base_q + reference_joints.index(name) for name in joints]
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng, samples)
    v = rng.normal(size=(samples, robot.nv))
    a = rng.normal(size=(samples, robot.nv))

    def to_reference(x: np.ndarray, order: list[int]) -> np.ndarray:
        out = np.empty_like(x)
        out[:, order] = x
        return out

    def from_reference(x: np.ndarray) -> np.ndarray:
        return x[:, v_order] if x.ndim == 2 else x[:, v_order][:, :, v_order]

    q_ref, v_ref, a_ref = to_reference(q, q_order), to_reference(v, v_order), to_reference(a, v_order)
    reference_values = {
        "tau": from_reference(model.inverse_dynamics(q_ref, v_ref, a_ref)),
        "M": from_reference(model.mass_matrix(q_ref)),
        "Cv": from_reference(model.coriolis_forces(q_ref, v_ref)),
        "G": from_reference(model.gravity(q_ref)),
    }
    coriolis = robot.coriolis_matrix(q, v)
    pinocchio_values = {
        "tau": robot.inverse_dynamics(q, v, a),
        "M": robot.mass_matrix(q),
        "Cv": np.einsum("nij,nj->ni", coriolis, v),
        "C": coriolis,
        "G": robot.gravity(q),
    }
    report = CheckReport(robot.name, samples, seed, list(robot.joint_names))
    # A term that vanishes (C of a single joint, G of joints on vertical axes) is compared
    # relative to its natural size: M times speeds, or the torques of the same states.
    mass_scale, speed, torque_scale = _largest(reference_values["M"]), _largest(v), _largest(reference_values["tau"])
    floors = {"tau": 0.0, "M": 0.0, "Cv": mass_scale * speed**2, "C": mass_scale * speed, "G": torque_scale}
    for name in reference_values:
        report.comparisons[name] = _compare(pinocchio_values[name], reference_values[name], tolerance, floors[name])
    if robot.floating_base:  # C (and Ṁ − 2C) are in other coordinates there: τ, M, C v, G suffice
        return report

    reference_values["C"] = from_reference(model.coriolis_matrix(q_ref, v_ref))
    report.comparisons["C"] = _compare(coriolis, reference_values["C"], tolerance, floors["C"])
    step = 1e-6
    m_dot = (robot.mass_matrix(q + step * v) - robot.mass_matrix(q - step * v)) / (2 * step)
    # Relative to the size of Ṁ, or of M times the speeds when Ṁ happens to be tiny
    # (the finite difference's rounding error scales with M, not with Ṁ).
    scale = max(_largest(m_dot), mass_scale * speed)
    report.comparisons["skew_pinocchio"] = _skewness(m_dot - 2 * coriolis, scale, FINITE_DIFFERENCE_TOLERANCE)
    m_dot_reference = from_reference(model.mass_matrix_derivative(q_ref, v_ref))
    report.comparisons["skew_reference"] = _skewness(m_dot_reference - 2 * reference_values["C"], scale, tolerance)
    return report


def report_dict(report: CheckReport) -> dict:
    """A JSON-ready form of a report."""
    return {
        "robot": report.robot,
        "samples": report.samples,
        "seed": report.seed,
        "joint_names": report.joint_names,
        "passed": report.passed,
        "comparisons": {
            name: {"max_abs": c.max_abs, "max_rel": c.max_rel, "tolerance": c.tolerance, "passed": c.passed}
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
}


def report_text(report: CheckReport) -> str:
    """A readable table of a report."""
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
    return "\n".join(lines)
