"""Base parameters: the combinations of the standard parameters that motion can identify.

Gautier's numerical method. The regressor ``Y`` (:mod:`robodyn.dynamics.regressor`) is
stacked at ``samples`` random states (``q`` uniform within the joint limits, ``v`` and ``a``
standard normal) into ``W`` (samples·nv rows), each column scaled to unit length (columns
of norm ≤ ``tolerance`` times the largest are zero: those parameters do not act on τ).
Joints whose URDF limits are equal are sampled in [−π, π] (:func:`joint_ranges`).

- The rank ``r`` comes from a QR decomposition **with column pivoting** of ``W``: the
  number of ``|R_ii|`` above ``tolerance · |R_00|``.
- The ``r`` independent columns are chosen in the standard order (first body first,
  ``m, m·c, I`` within a body): column ``j`` is kept when its part orthogonal to the columns
  before it (``|R_jj|`` of the unpivoted QR) exceeds the same tolerance. Both counts must
  agree.
- The other columns are exact combinations ``W_D = W_I B`` (least squares, residual
  checked), so ``Y π = Y_I β`` with the base parameters ``β = π_I + B π_D``; the map
  standard → base is ``K`` (r × p) with ``K[:, I] = 1`` and ``K[:, D] = B``.
- Stability: the whole construction is done twice, at two independent draws of states
  (``seed`` and ``seed + 1``); the independent set and ``K`` must agree, or the call is
  refused.

Each base parameter is named after its independent standard parameter (e.g.
``"Izz[link1]"``); :meth:`BaseParameters.expressions` gives it in the standard ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import scipy.linalg

from robodyn.dynamics.regressor import body_links, inertial_parameters, parameter_names, regressor
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import IdentificationError, InputError

#: Default relative rank tolerance on the column-scaled stacked regressor.
TOLERANCE = 1e-8
#: Coefficients of ``K`` below this (relative to 1) are rounding and are set to zero.
COEFFICIENT_ZERO = 1e-10
#: Largest number of joints for which :meth:`BaseParameters.expressions` is offered.
SYMBOLIC_MAX_JOINTS = 7


def joint_ranges(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """Position ranges of the joints (a floating base's six coordinates left out), in [rad]
    or [m]: the URDF's limits, except that unlimited joints and joints whose limits are
    equal (``lower = upper``, which published URDFs write for "no limit") get [−π, π].

    Args:
        robot: The robot.
    """
    lower, upper = robot.lower_limits.copy(), robot.upper_limits.copy()
    if robot.floating_base:
        lower, upper = lower[6:], upper[6:]
    free = ~(np.isfinite(lower) & np.isfinite(upper) & (upper > lower))
    return np.where(free, -np.pi, lower), np.where(free, np.pi, upper)


def random_states(robot: Robot, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` random states: q uniform in :func:`joint_ranges` (a floating base's pose
    as :meth:`Robot.random_configuration`), v and a standard normal.

    Args:
        robot: The robot.
        count: Number of states.
        rng: The random generator.
    """
    q = robot.random_configuration(rng, count)
    lower, upper = joint_ranges(robot)
    q[:, q.shape[1] - lower.size :] = rng.uniform(lower, upper, size=(count, lower.size))
    return q, rng.standard_normal((count, robot.nv)), rng.standard_normal((count, robot.nv))


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a robot (see the module docstring).

    Attributes:
        robot: The robot.
        count: Number of base parameters ``r``.
        names: Name of each base parameter (its independent standard parameter), (r,).
        values: Base parameter values of the robot's URDF, ``K π``, shape (r,).
        mapping: ``K``, shape (r, p): base = ``K @ standard`` (over :attr:`columns`).
        standard_names: Names of the p standard parameters ``K`` acts on.
        columns: Indices of those p parameters in the full standard vector (all of them
            unless ``bodies`` was given).
        independent: Indices (into :attr:`columns`) of the independent standard parameters.
        friction: Whether the friction parameters are included.
        tolerance: Relative rank tolerance used.
        samples: Number of random states stacked.
        seed: Seed of the first draw (the stability check used ``seed + 1`` too).
    """

    robot: Robot
    count: int
    names: list[str]
    values: np.ndarray
    mapping: np.ndarray
    standard_names: list[str]
    columns: np.ndarray
    independent: np.ndarray
    friction: bool
    tolerance: float
    samples: int
    seed: int
    _standard: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))

    def standard_regressor(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The full standard regressor (friction columns if :attr:`friction`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        return regressor(self.robot, q, v, a, friction=self.friction)

    def regressor(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Base regressor ``Y_b`` with ``Y_b β = Y π`` over :attr:`columns`.

        Args:
            q, v, a: States, shape (nq,)/(nv,) or (N, nq)/(N, nv).

        Returns:
            Shape (nv, count) or (N, nv, count).
        """
        return self.standard_regressor(q, v, a)[..., self.columns[self.independent]]

    def known_torque(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Torque of the parameters outside :attr:`columns` (held at the URDF's values) and
        of the joints' armature (``armature ⊙ a``, no parameter of the regressor), shape
        (nv,) or (N, nv); zero when every parameter is included and there is no armature.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        full = self.standard_regressor(q, v, a)
        rest = np.setdiff1d(np.arange(full.shape[-1]), self.columns)
        return full[..., rest] @ self._standard[rest] + self.robot.joint_armature * np.asarray(a, dtype=float)

    def to_base(self, standard: np.ndarray) -> np.ndarray:
        """Base values of a standard parameter vector over :attr:`columns`, (p,) -> (r,).

        Args:
            standard: Standard parameters, shape (p,), in the order of :attr:`standard_names`, their units.
        """
        return self.mapping @ np.asarray(standard, dtype=float)

    def expressions(self) -> list:
        """Each base parameter as a sympy expression in the standard parameters.

        Symbols are named as :attr:`standard_names` (``m[link1]``, ...); coefficients that
        are rationals to 1e-12 (lengths like 0.5 m give 1/2, 1/4) are written exactly,
        others as floats.

        Raises:
            IdentificationError: For robots with more than ``SYMBOLIC_MAX_JOINTS`` joints.
        """
        import sympy as sp

        if self.robot.nv > SYMBOLIC_MAX_JOINTS:
            raise IdentificationError(
                self.robot.name,
                f"symbolic base parameters are offered up to {SYMBOLIC_MAX_JOINTS} joints, it has {self.robot.nv}",
            )
        symbols = [sp.Symbol(name, real=True) for name in self.standard_names]
        return [sp.Add(*[_exact(c) * symbols[j] for j, c in enumerate(row) if c != 0.0], evaluate=True) for row in self.mapping]


def _exact(value: float):
    import sympy as sp

    fraction = Fraction(value).limit_denominator(10_000)
    if abs(float(fraction) - value) <= 1e-12 * max(1.0, abs(value)):
        return sp.Rational(fraction.numerator, fraction.denominator)
    return sp.Float(value, 15)


def _decompose(w: np.ndarray, tolerance: float, robot: str) -> tuple[np.ndarray, np.ndarray]:
    """Independent column indices and ``K`` of a stacked regressor ``w`` (rows × p).

    Everything is done on the triangular factor ``R0`` of ``w = Q0 R0`` (p × p), which has
    the same column geometry: the pivoted and ordered QRs and the least-squares fit of the
    dependent columns are those of ``w``.
    """
    norms = np.linalg.norm(w, axis=0)
    active = norms > tolerance * norms.max()
    scaled = np.where(active, w / np.where(active, norms, 1.0), 0.0)
    r_plain = scipy.linalg.qr(scaled, mode="r")[0][: w.shape[1]]
    _, r_pivoted, _ = scipy.linalg.qr(r_plain, pivoting=True)
    diagonal = np.abs(np.diag(r_pivoted))
    rank = int(np.sum(diagonal > tolerance * diagonal[0]))
    plain = np.abs(np.diag(r_plain))
    independent = np.flatnonzero((plain > tolerance * diagonal[0]) & active)
    if independent.size != rank:
        raise IdentificationError(
            robot,
            f"the base parameters are ill-determined: pivoted QR gives rank {rank}, the ordered choice {independent.size} "
            f"(tolerance {tolerance:g}); draw more samples or change the tolerance",
        )
    dependent = np.setdiff1d(np.arange(w.shape[1]), independent)
    unscaled = r_plain * np.where(active, norms, 0.0)  # R0 of w itself (columns scaled back)
    combination = np.linalg.lstsq(unscaled[:, independent], unscaled[:, dependent], rcond=None)[0]
    combination[:, ~active[dependent]] = 0.0  # columns that do not act on tau
    residual = np.linalg.norm(unscaled[:, independent] @ combination - unscaled[:, dependent], axis=0)
    worst = float(np.max(residual[active[dependent]] / norms[dependent][active[dependent]], initial=0.0))
    if worst > 1e3 * tolerance:
        raise IdentificationError(
            robot, f"a dependent column is not a combination of the independent ones (residual {worst:.3g})"
        )
    combination[np.abs(combination) < COEFFICIENT_ZERO] = 0.0
    mapping = np.zeros((rank, w.shape[1]))
    mapping[:, independent] = np.eye(rank)
    mapping[:, dependent] = combination
    return independent, mapping


def _select_columns(robot: Robot, bodies: Sequence[str] | None, friction: bool) -> np.ndarray:
    links = body_links(robot)
    total = 10 * len(links) + (2 * robot.nv if friction else 0)
    if bodies is None:
        return np.arange(total)
    unknown = [name for name in bodies if name not in links]
    if unknown or not bodies:
        raise InputError("bodies", f"link names of moving bodies ({', '.join(links)})", repr(list(bodies)))
    columns = [10 * links.index(name) + k for name in dict.fromkeys(bodies) for k in range(10)]
    return np.array(columns + list(range(10 * len(links), total)))


def base_parameters(
    robot: Robot,
    *,
    samples: int | None = None,
    tolerance: float = TOLERANCE,
    seed: int = 0,
    friction: bool = False,
    bodies: Sequence[str] | None = None,
) -> BaseParameters:
    """The base parameters of ``robot`` (Gautier's numerical method, module docstring).

    Args:
        robot: The robot.
        samples: Random states stacked; default ``max(100, 3 p / nv)`` (rows ≥ 3 × columns).
        tolerance: Relative rank tolerance on the column-scaled stacked regressor.
        seed: Seed of the first draw of states (the check draws ``seed + 1``).
        friction: Include viscous and Coulomb friction parameters (always identifiable).
        bodies: Only these bodies' parameters (link names, see
            :func:`robodyn.dynamics.regressor.body_links`) are unknown; the others are
            held at the URDF's values (their torque is :meth:`BaseParameters.known_torque`).

    Raises:
        IdentificationError: If the two draws disagree (count or combinations), or the
            rank decision is ambiguous.
        InputError: For a bad ``samples``, ``tolerance`` or ``bodies``.
    """
    if not (isinstance(tolerance, float | int) and 0 < tolerance < 1e-2):
        raise InputError("tolerance", "a number in (0, 0.01)", repr(tolerance))
    columns = _select_columns(robot, bodies, friction)
    if samples is None:
        samples = max(100, int(np.ceil(3 * len(columns) / robot.nv)))
    if not (isinstance(samples, int) and samples * robot.nv >= len(columns)):
        raise InputError("samples", f"an integer ≥ {int(np.ceil(len(columns) / robot.nv))}", repr(samples))
    results = []
    for draw in (seed, seed + 1):
        q, v, a = random_states(robot, samples, np.random.default_rng(draw))
        w = regressor(robot, q, v, a, friction=friction)[..., columns].reshape(-1, len(columns))
        results.append(_decompose(w, tolerance, robot.name))
    (independent, mapping), (independent_2, mapping_2) = results
    if not np.array_equal(independent, independent_2) or not np.allclose(mapping, mapping_2, rtol=1e-6, atol=1e-8):
        raise IdentificationError(
            robot.name,
            f"the base parameters differ between two draws of states ({independent.size} and {independent_2.size} "
            f"parameters); use more samples or a looser tolerance than {tolerance:g}",
        )
    if independent.size == 0:
        raise IdentificationError(robot.name, "no inertial parameter acts on the joint torques (no mass moves, no gravity)")
    standard = inertial_parameters(robot, friction=friction)
    names = parameter_names(robot, friction=friction)
    return BaseParameters(
        robot=robot,
        count=int(independent.size),
        names=[names[columns[i]] for i in independent],
        values=mapping @ standard[columns],
        mapping=mapping,
        standard_names=[names[c] for c in columns],
        columns=columns,
        independent=independent,
        friction=friction,
        tolerance=float(tolerance),
        samples=samples,
        seed=seed,
        _standard=standard,
    )


__all__ = ["TOLERANCE", "BaseParameters", "base_parameters", "random_states"]
