"""Constrained dynamics on Pinocchio: ``Φ``, ``J``, ``J̇ v`` of a robot's constraints, and the KKT solves.

The rows of each constraint are :mod:`robodyn.constraints.algebra`'s; Pinocchio supplies
the kinematics of their ends from one pass a state (:mod:`robodyn.dynamics.constraint_rows`:
each end a frame of a copy of the model, so its placement, ``LOCAL_WORLD_ALIGNED`` Jacobian
and classical acceleration at ``v̇ = 0`` are taken at its own point).

**Forward dynamics** solves the KKT system of ``M v̇ + C v + G = τ + Jᵀ λ`` with
``J v̇ + J̇ v = 0`` by its own factorisation, not Pinocchio's ``constraintDynamics``:
``M⁻¹ (τ − C v − G)`` and ``M⁻¹ Jᵀ`` from one Cholesky factorisation of robodyn's ``M`` (so
mimic joints and armature are included, which Pinocchio's constraint algorithms do not
take), the Delassus matrix ``A = J M⁻¹ Jᵀ`` and ``λ = A⁺ b`` by its eigendecomposition,
eigenvalues below :data:`RANK_TOLERANCE` times the largest dropped (above
:data:`EIGEN_ROWS` rows a Cholesky factorisation of ``A`` answers first when a bound on its
condition proves nothing would be dropped). The factorisations are Eigen's, through
eigenpy (Pinocchio's own bindings): for matrices this small, numpy's wrappers cost more
than the work. For a redundant set (a planar four-bar closed by a 3-row point anchor, where
one row repeats the others) that is the least-norm ``λ``: the limit of the proximal
iteration ``(A + ρ I) λₖ₊₁ = b + ρ λₖ`` from ``λ₀ = 0`` (what Pinocchio's
``ProximalSettings`` runs), computed in one step. ``v̇`` is unique either way;
:func:`constraint_rank` reports how many rows are independent. Pinocchio's
``constraintDynamics`` is the outside check (tests/dynamics/test_constrained.py).

Inner loops (:func:`state_rows`, :func:`forward_dynamics_unchecked`) get the last state's
results again, read-only, when asked for the same state (a simulation's projection and its
next step's first stage); the public functions return arrays of their own.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import eigenpy
import numpy as np
import pinocchio as pin

from robodyn.constraints import Constraint, as_constraints, check_frames
from robodyn.constraints.algebra import Bound, bind
from robodyn.dynamics.constraint_rows import EndFrames
from robodyn.dynamics.inertia_rank import refuse_singular, singular_error
from robodyn.exceptions import InputError, NonFiniteResultError, SingularMassMatrixError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

#: Eigenvalues of the Delassus matrix below this times the largest are redundant rows.
RANK_TOLERANCE = 1e-10
#: Delassus matrices of more rows than this try a Cholesky factorisation (and a bound on
#: their condition) before an eigendecomposition: for fewer, the eigendecomposition of
#: Eigen (through eigenpy, Pinocchio's bindings) costs no more than the test.
EIGEN_ROWS = 6
#: Largest unbalanced force on the unactuated rows, relative to ``max |M a + C v + G|``
#: (and 1), that :func:`contact_inverse_dynamics` accepts.
BALANCE_TOLERANCE = 1e-8

_SUCCESS = eigenpy.ComputationInfo.Success

_BOUND: weakref.WeakKeyDictionary[Any, dict[tuple[Constraint, ...], tuple[Bound, ...]]] = weakref.WeakKeyDictionary()


def bound(robot: Robot, constraints: object) -> tuple[Bound, ...]:
    """The robot's constraints (``None``: :attr:`Robot.constraints`) with both ends resolved.

    Args:
        robot: The robot the constraints act on.
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).

    Raises:
        InputError: For anything that is not a constraint, or a link the robot does not have.
    """
    given = robot.constraints if constraints is None else as_constraints(constraints)
    cache = _BOUND.setdefault(robot, {})
    if given not in cache:
        check_frames(given, list(robot.spec.links), robot.name)
        model, data, frames = robot.model, pin.Model.createData(robot.model), robot.handle.frames
        pin.framesForwardKinematics(model, data, pin.neutral(model))

        def pose(link: str) -> tuple[np.ndarray, np.ndarray]:
            placement = data.oMf[frames[link]]
            return placement.rotation.copy(), placement.translation.copy()

        cache[given] = bind(given, pose)
    return cache[given]


_ENDS: weakref.WeakKeyDictionary[Any, dict[tuple[Bound, ...], EndFrames]] = weakref.WeakKeyDictionary()


def end_frames(robot: Robot, bounds: tuple[Bound, ...]) -> EndFrames:
    """The rows of ``bounds`` (from :func:`bound`) on ``robot``, made once a set.

    Args:
        robot: The robot the constraints act on.
        bounds: Its constraints bound to its frames (:func:`bound`).
    """
    cache = _ENDS.setdefault(robot, {})
    ends = cache.get(bounds)
    if ends is None:
        ends = cache[bounds] = EndFrames(robot, bounds)
    return ends


def state_rows(robot: Robot, bounds: tuple[Bound, ...], q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
    """``Φ`` (m,), ``J`` (m, nv), ``J̇ v`` (m,) at one checked state, for inner loops: the
    arrays are read-only, and shared with the next call at the same state
    (:meth:`~robodyn.dynamics.constraint_rows.EndFrames.rows`).

    Args:
        robot: The robot the constraints act on.
        bounds: Its constraints bound to its frames (:func:`bound`).
        q: Configuration, float64, shape (nq,).
        v: Velocity, float64, shape (nv,).
    """
    return end_frames(robot, bounds).rows(q, v)


def _per_state(
    robot: Robot, function: Callable[..., tuple[np.ndarray, ...]], batch: bool, *arrays: np.ndarray
) -> tuple[np.ndarray, ...]:
    """``function`` of one state, or of each row of a batch (results stacked; an empty
    batch gives empty stacks of the right shapes, from one call at the neutral state)."""
    if not batch:
        return function(*arrays)
    results = [function(*row) for row in zip(*arrays, strict=True)]
    if not results:
        neutral = [robot.neutral_configuration(), *(np.zeros(array.shape[1]) for array in arrays[1:])]
        return tuple(np.zeros((0, *np.shape(value))) for value in function(*neutral))
    return tuple(np.array([result[k] for result in results]) for k in range(len(results[0])))


def _finite(robot: Robot, what: str, compute: Callable[[], tuple[np.ndarray, ...]]) -> tuple[np.ndarray, np.ndarray]:
    """``compute()``'s two arrays, or a :class:`NonFiniteResultError` when finite inputs
    overflowed (an eigendecomposition of non-finite numbers included): never a NaN."""
    try:
        with np.errstate(all="ignore"):  # an overflow is refused below, not warned about
            first, second = compute()
    except np.linalg.LinAlgError:
        raise NonFiniteResultError(robot.name, what) from None
    if not (np.isfinite(first).all() and np.isfinite(second).all()):
        raise NonFiniteResultError(robot.name, what)
    return first, second


def constraint_residual(robot: Robot, q: np.ndarray, constraints: object = None) -> np.ndarray:
    """``Φ(q)``, shape (m,) or (N, m) (see :mod:`robodyn.constraints.algebra`), in [m] / [rad].

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).
    """
    bounds = bound(robot, constraints)
    (q,), batch = robot.validate(q=q)
    zeros = np.zeros(robot.nv)
    return _per_state(robot, lambda qi: end_frames(robot, bounds).compute(qi, zeros)[:1], batch, q)[0]


def constraint_jacobian(robot: Robot, q: np.ndarray, constraints: object = None) -> np.ndarray:
    """``J(q)``, shape (m, nv) or (N, m, nv): the rows' velocities are ``J v``.

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).
    """
    bounds = bound(robot, constraints)
    (q,), batch = robot.validate(q=q)
    zeros = np.zeros(robot.nv)
    return _per_state(robot, lambda qi: end_frames(robot, bounds).compute(qi, zeros)[1:2], batch, q)[0]


def constraint_drift(robot: Robot, q: np.ndarray, v: np.ndarray, constraints: object = None) -> np.ndarray:
    """``J̇(q, v) v``, shape (m,) or (N, m): the rows' accelerations at ``v̇ = 0``.

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).
    """
    bounds = bound(robot, constraints)
    (q, v), batch = robot.validate(q=q, v=v)
    return _per_state(robot, lambda qi, vi: end_frames(robot, bounds).compute(qi, vi)[2:], batch, q, v)[0]


def constraint_rank(robot: Robot, q: np.ndarray, constraints: object = None) -> int:
    """How many rows of the constraints are independent at one configuration (rank of ``J``;
    rows minus rank are redundant).

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,), in [rad] / [m].
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).
    """
    jacobian = constraint_jacobian(robot, np.asarray(q, float).reshape(-1), constraints)
    if not jacobian.size:
        return 0
    singular = np.linalg.svd(jacobian, compute_uv=False)
    return int(np.sum(singular > RANK_TOLERANCE * max(singular[0], 1e-300)))


def solve_kkt(
    mass: np.ndarray, force: np.ndarray, jacobian: np.ndarray, drift: np.ndarray, name: str = "robot"
) -> tuple[np.ndarray, np.ndarray]:
    """``(v̇, λ)`` of ``M v̇ = force + Jᵀ λ``, ``J v̇ = −drift`` (λ least-norm; module docstring).

    Args:
        mass: The mass matrix ``M``, shape (nv, nv), positive definite.
        force: ``tau − C v − G``, shape (nv,), in [N m] / [N].
        jacobian: The constraints' Jacobian ``J``, shape (m, nv).
        drift: ``J̇ v``, shape (m,).
        name: The robot's name, for the error.

    Raises:
        SingularMassMatrixError: If ``M`` is not positive definite.
        numpy.linalg.LinAlgError: If the Delassus matrix's eigendecomposition does not converge
            (non-finite numbers).
    """
    if not len(force):
        return np.zeros(0), np.zeros(len(drift))
    cholesky = eigenpy.LLT(mass)  # M is positive definite (no massless subtree): one Cholesky factorisation
    if cholesky.info() != _SUCCESS:
        raise SingularMassMatrixError(name, [])
    free = cholesky.solve(force).reshape(-1)  # eigenpy returns a vector or a column matrix: shapes made sure
    if not len(drift):
        return free, np.zeros(0)
    response = cholesky.solve(jacobian.T).reshape(len(free), len(drift))  # M⁻¹ Jᵀ
    multipliers = _least_norm(jacobian @ response, -(drift + jacobian @ free))
    return free + response @ multipliers, multipliers


def _least_norm(delassus: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``A⁺ b`` of the Delassus matrix ``A`` (symmetric: its lower triangle is read), its
    eigenvalues below :data:`RANK_TOLERANCE` times the largest dropped.

    Above :data:`EIGEN_ROWS` rows a Cholesky factorisation comes first and answers when a
    bound proves no eigenvalue is dropped (``λ_min ≥ 1 / tr A⁻¹``, ``λ_max ≤ tr A``); else,
    and for fewer rows (where the eigendecomposition costs no more than that test), ``A``'s
    eigendecomposition gives the least-norm ``λ``.
    """
    if len(target) > EIGEN_ROWS:
        cholesky = eigenpy.LLT(delassus)
        if cholesky.info() == _SUCCESS:
            inverse = cholesky.solve(np.eye(len(target))).reshape(len(target), len(target))
            if RANK_TOLERANCE * float(delassus.trace()) * float(inverse.trace()) < 1.0:
                return inverse @ target
    eigen = eigenpy.SelfAdjointEigenSolver(delassus)
    if eigen.info() != _SUCCESS:
        raise np.linalg.LinAlgError("the Delassus matrix's eigendecomposition did not converge")
    values, vectors = eigen.eigenvalues(), eigen.eigenvectors()  # the solver's own arrays: used while it lives
    floor, kept = RANK_TOLERANCE * max(float(values[-1]), 1e-300), 0  # values ascending
    while kept < len(values) and values[kept] <= floor:
        kept += 1
    return vectors[:, kept:] @ ((target @ vectors[:, kept:]) / values[kept:])


def forward_dynamics(
    robot: Robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray, constraints: object = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(v̇, λ)`` under bilateral constraints: shapes (nv,), (m,) or (N, nv), (N, m).

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        tau: Joint torques / forces, shape (nv,) or (N, nv), in [N m] / [N].
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).
    """
    bounds = bound(robot, constraints)
    (q, v, tau), batch = robot.validate(q=q, v=v, tau=tau)
    if robot.massless_joints:
        raise SingularMassMatrixError(robot.name, robot.massless_joints)

    try:
        a, multipliers = _finite(
            robot,
            "constrained dynamics",
            lambda: _per_state(robot, lambda *state: _dynamics(robot, bounds, *state), batch, q, v, tau),
        )
    except SingularMassMatrixError as error:  # M not positive definite at some state: name its joints
        raise (error if error.joints else singular_error(robot, q)) from None
    refuse_singular(robot, q, a)  # a round-off pivot of M's Cholesky factor? (M's rank looked at only for huge a)
    return a, multipliers


def forward_dynamics_unchecked(
    robot: Robot, bounds: tuple[Bound, ...], q: np.ndarray, v: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`forward_dynamics` of one checked state (float64 1-D arrays of the right sizes)
    and bound constraints (:func:`bound`), for inner loops (simulation): the arrays are
    read-only, and shared with the next call at the same state and torques.

    Args:
        robot: The robot the constraints act on.
        bounds: Its constraints bound to its frames (:func:`bound`).
        q: Configuration, float64, shape (nq,).
        v: Velocity, float64, shape (nv,).
        tau: Torques, float64, shape (nv,), in [N m] / [N].
    """
    return end_frames(robot, bounds).remember("dynamics", (q, v, tau), lambda: _dynamics(robot, bounds, q, v, tau))


def _dynamics(
    robot: Robot, bounds: tuple[Bound, ...], q: np.ndarray, v: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(v̇, λ)`` of one checked state."""
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    _, jacobian, drift = state_rows(robot, bounds, q, v)
    return solve_kkt(mass, tau - bias, jacobian, drift, robot.name)


def contact_inverse_dynamics(
    robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, constraints: object = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(τ, λ)`` with ``M a + C v + G = τ + Jᵀ λ`` and ``τ = 0`` on the unactuated coordinates.

    ``λ`` is the least-norm solution of the unactuated rows ``Sᵤ Jᵀ λ = Sᵤ (M a + C v + G)``
    (a floating base's six: the constraints carry the base); ``τ`` is what remains for the
    actuated coordinates. When every coordinate is actuated, ``λ = 0``.

    Args:
        robot: The robot the constraints act on.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        constraints: The constraints: one :class:`~robodyn.constraints.values.PointAnchor`,
            :class:`~robodyn.constraints.values.FrameAnchor` or :class:`~robodyn.constraints.values.PointContact`, an iterable
            of them, or ``None`` for the robot's own (:attr:`robodyn.Robot.constraints`).

    Raises:
        InputError: If no multipliers balance the unactuated rows (``a`` is not reachable
            with these constraints), naming the unbalanced force.
    """
    bounds = bound(robot, constraints)
    (q, v, a), batch = robot.validate(q=q, v=v, a=a)
    unactuated = [dof.index for dof in robot.dofs if not dof.actuated]

    def one(qi: np.ndarray, vi: np.ndarray, ai: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        force = robot.inverse_dynamics(qi, vi, ai)
        _, jacobian, _ = state_rows(robot, bounds, qi, vi)
        multipliers = np.zeros(len(jacobian))
        if unactuated and len(jacobian):
            multipliers = np.linalg.lstsq(jacobian.T[unactuated], force[unactuated], rcond=RANK_TOLERANCE)[0]
        tau = force - jacobian.T @ multipliers
        unbalanced = float(np.max(np.abs(tau[unactuated]), initial=0.0))
        if unbalanced > BALANCE_TOLERANCE * max(1.0, float(np.max(np.abs(force)))):
            raise InputError(
                "a",
                "an acceleration the constraints and the actuated joints can produce",
                f"{unbalanced:.3g} unbalanced on the unactuated coordinates",
            )
        tau[unactuated] = 0.0
        return tau, multipliers

    return _finite(robot, "contact inverse dynamics", lambda: _per_state(robot, one, batch, q, v, a))


__all__ = [
    "RANK_TOLERANCE",
    "bound",
    "constraint_drift",
    "constraint_jacobian",
    "constraint_rank",
    "constraint_residual",
    "contact_inverse_dynamics",
    "forward_dynamics",
    "forward_dynamics_unchecked",
    "solve_kkt",
    "state_rows",
]
