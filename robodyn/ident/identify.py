"""Identification of the base parameters from measured motion and torques.

The data are N samples of ``(q, v, a, tau)`` (e.g. a :class:`robodyn.trajectory.Trajectory`).
Stacking the base regressor gives the overdetermined system ``W β = y`` with
``y = tau − known torque`` (N·nv rows).

- ``"ls"``: ordinary least squares. With residual ``e``, ``σ² = |e|² / (N·nv − r)`` and
  ``cov(β) = σ² (WᵀW)⁻¹``; the standard deviations are the square roots of its diagonal.
- ``"wls"``: weighted least squares (Gautier): each joint's noise level ``σ_j`` is estimated
  from its rows of the LS residual, the rows are divided by ``σ_j`` and the system is solved
  again; ``cov(β) = (Wᵀ Σ⁻¹ W)⁻¹``.
- ``"physical"``: the standard parameters π themselves, constrained to physically consistent
  bodies — each body's pseudo-inertia ``J = [[½ tr(Ī) 1 − Ī, m c], [(m c)ᵀ, m]]`` positive
  semidefinite (Wensing, Kim, Slotine 2017), friction coefficients non-negative — minimising
  the WLS residual of the base parameters ``K π`` plus a small pull ``λ |π − π_URDF|²``
  that picks, among the standard sets with the same base parameters, the one nearest the
  URDF. A semidefinite program solved by
  cvxpy (Clarabel, else SCS). Its standard deviations are those of the WLS estimate.

The relative prediction error is ``|tau − tau_predicted| / |tau|`` (Frobenius norms).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import IdentificationError, InputError
from robodyn.ident.base import BaseParameters, base_parameters


class Samples(Protocol):
    """Measured data: anything with these attributes, e.g. a
    :class:`robodyn.trajectory.Trajectory` (``joint_names`` may be empty)."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    joint_names: list[str]


#: Estimators: least squares, weighted least squares, physically consistent (module docstring).
Method = Literal["ls", "wls", "physical"]
METHODS: tuple[Method, ...] = ("ls", "wls", "physical")


@dataclass
class Identification:
    """The result of :func:`identify`.

    Attributes:
        method: ``"ls"``, ``"wls"`` or ``"physical"``.
        base: The base parameter set identified (names, the URDF's values, the map).
        values: Identified base parameters, shape (count,).
        std: Their standard deviations, shape (count,).
        covariance: Shape (count, count).
        relative_error: ``|tau − predicted| / |tau|`` on the data.
        rms_error: RMS torque error per joint on the data, shape (nv,), in [N m] / [N].
        condition: Condition number of the stacked base regressor of the data.
        standard: For ``"physical"``: the full standard parameters over ``base.columns``
            (physically consistent), else ``None``.
        samples: Number of samples used.
    """

    method: str
    base: BaseParameters
    values: np.ndarray
    std: np.ndarray
    covariance: np.ndarray
    relative_error: float
    rms_error: np.ndarray
    condition: float
    samples: int
    standard: np.ndarray | None = None
    solver: str | None = field(default=None)

    def predict(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Predicted torques ``Y_b β + known``, shape (nv,) or (N, nv).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        return self.base.regressor(q, v, a) @ self.values + self.base.known_torque(q, v, a)

    def prediction_error(self, trajectory: Samples, tau: np.ndarray | None = None) -> float:
        """Relative torque prediction error on other data (a validation trajectory).

        Args:
            trajectory: Validation data with ``q``, ``v``, ``a`` and ``tau`` (e.g. a :class:`robodyn.trajectory.Trajectory`).
            tau: Measured torques in [N m] / [N], shape (N, nv), instead of ``trajectory.tau`` (``None``: those).
        """
        measured = trajectory.tau if tau is None else np.asarray(tau, dtype=float)
        predicted = self.predict(trajectory.q, trajectory.v, trajectory.a)
        return float(np.linalg.norm(measured - predicted) / np.linalg.norm(measured))

    def to_dict(self) -> dict:
        """JSON-ready summary (names, values, std, the URDF's values, errors)."""
        result = {
            "robot": self.base.robot.name,
            "method": self.method,
            "samples": self.samples,
            "relative_error": self.relative_error,
            "rms_error": self.rms_error.tolist(),
            "joint_names": self.base.robot.joint_names,
            "condition": self.condition,
            "base_parameters": [
                {"name": name, "value": float(value), "std": float(std), "urdf": float(urdf)}
                for name, value, std, urdf in zip(self.base.names, self.values, self.std, self.base.values, strict=True)
            ],
        }
        if self.standard is not None:
            result["standard_parameters"] = {
                name: float(value) for name, value in zip(self.base.standard_names, self.standard, strict=True)
            }
            result["solver"] = self.solver
        return result


def _data(robot: Robot, trajectory: Samples, tau: np.ndarray | None) -> tuple[np.ndarray, ...]:
    names = list(trajectory.joint_names)
    per_coordinate = robot.floating_base and len(names) == robot.nv  # a floating base's six coordinates named apart
    if names and names != list(robot.joint_names) and not per_coordinate:
        raise IdentificationError(
            robot.name, f"the data's joints {trajectory.joint_names!r} are not the robot's {robot.joint_names!r}"
        )
    tau = trajectory.tau if tau is None else tau
    (q, v, a, tau), batch = robot.validate(q=trajectory.q, v=trajectory.v, a=trajectory.a, tau=tau)
    if not batch or len(q) == 0:
        raise InputError("trajectory", "one state a row (2-D arrays with at least one row)", f"shape {np.shape(q)}")
    return q, v, a, tau


def identify(
    robot: Robot,
    trajectory: Samples,
    tau: np.ndarray | None = None,
    *,
    method: Method = "ls",
    base: BaseParameters | None = None,
    friction: bool = False,
) -> Identification:
    """Identify the base parameters of ``robot`` from measured motion and torques.

    Args:
        robot: The nominal robot (its kinematics are trusted, its inertias are not).
        trajectory: Measured ``q`` (N, nq), ``v`` and ``a`` (N, nv) (``trajectory.tau`` is
            the measured torque unless ``tau`` is given).
        tau: Measured torques, shape (N, nv), in [N m] / [N].
        method: ``"ls"``, ``"wls"`` or ``"physical"`` (module docstring).
        base: The base parameter set to identify; default :func:`base_parameters` of the
            robot (with ``friction``). Give one built with ``bodies=`` to identify only some
            bodies (e.g. a payload's carrier) with the others held at the URDF's values.
        friction: With the default ``base``, identify viscous and Coulomb friction too.

    Returns:
        The :class:`Identification`.

    Raises:
        IdentificationError: If the data do not excite every base parameter (rank-deficient
            regressor), have too few samples, or the solver fails.
        InputError: For an unknown method or malformed data.
    """
    if method not in METHODS:
        raise InputError("method", f"one of {', '.join(METHODS)}", repr(method))
    q, v, a, measured = _data(robot, trajectory, tau)
    base = base_parameters(robot, friction=friction) if base is None else base
    if base.robot is not robot:
        raise InputError("base", f"base parameters of robot {robot.name!r}", f"those of {base.robot.name!r}")
    full = base.standard_regressor(q, v, a)
    rest = np.setdiff1d(np.arange(full.shape[-1]), base.columns)
    target = measured - full[..., rest] @ base._standard[rest] - robot.joint_armature * a  # known: held parameters, armature
    w = full[..., base.columns[base.independent]]  # (N, nv, r)
    n, nv, r = w.shape
    if n * nv <= r:
        raise IdentificationError(robot.name, f"{n} samples × {nv} joints are too few for {r} base parameters")
    singular = np.linalg.svd(w.reshape(-1, r), compute_uv=False)
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else np.inf
    if not singular[-1] > 1e-10 * singular[0]:
        raise IdentificationError(
            robot.name,
            f"the data do not excite every base parameter (condition number {condition:.3g}); use an exciting trajectory",
        )
    values, covariance = _least_squares(w.reshape(-1, r), target.reshape(-1), np.ones(n * nv))
    weights = np.ones((n, nv))
    if method in ("wls", "physical"):
        residual = (target - w @ values).reshape(n, nv)
        sigma = np.sqrt(np.sum(residual**2, axis=0) / max(n - r / nv, 1.0))
        sigma = np.maximum(sigma, 1e-12 * float(sigma.max())) if sigma.max() > 0 else np.ones(nv)  # exact data: LS
        weights = np.broadcast_to(1.0 / sigma, (n, nv))
        values, covariance = _least_squares(w.reshape(-1, r), target.reshape(-1), weights.reshape(-1), weighted=True)
    standard, solver = None, None
    if method == "physical":
        from robodyn.ident.physical import physical_parameters

        standard, solver = physical_parameters(base, w, target, weights)
        values = base.to_base(standard)
    predicted = w @ values
    error = target - predicted
    return Identification(
        method=method,
        base=base,
        values=values,
        std=np.sqrt(np.maximum(np.diag(covariance), 0.0)),
        covariance=covariance,
        relative_error=float(np.linalg.norm(error) / (np.linalg.norm(measured) or 1.0)),
        rms_error=np.sqrt(np.mean(error**2, axis=0)),
        condition=condition,
        samples=n,
        standard=standard,
        solver=solver,
    )


def _least_squares(w: np.ndarray, y: np.ndarray, weights: np.ndarray, *, weighted: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Solution and covariance of ``diag(weights) (W β − y) → min``.

    Unweighted: ``cov = σ² (WᵀW)⁻¹`` with σ² from the residual; weighted (weights
    1/σ_row): ``cov = (Wᵀ Σ⁻¹ W)⁻¹``.
    """
    scaled = w * weights[:, None]
    values, *_ = np.linalg.lstsq(scaled, y * weights, rcond=None)
    inverse = np.linalg.pinv(scaled.T @ scaled)
    if weighted:
        return values, inverse
    rows, count = w.shape
    variance = float(np.sum((y - w @ values) ** 2) / (rows - count))
    return values, variance * inverse


__all__ = ["METHODS", "Identification", "identify"]
