"""Derivatives of the equations of motion: ∂τ/∂(q, v, a) and ∂q̈/∂(q, v, τ), by Pinocchio.

Functions of a :class:`~robodyn.dynamics.handle.ModelHandle`, Pinocchio style
(``inverse_dynamics_derivatives(handle, q, v, a)``); :class:`robodyn.Robot` has them as
methods. Pinocchio's analytical derivatives (Carpentier & Mansard, RSS 2018:
``computeRNEADerivatives``, ``computeABADerivatives``) compute them.

Conventions:
    - One state (1-D ``q``, ``v``, ``a`` or ``tau``) gives three matrices of shape
      (nv, nv); a batch (2-D, one state a row, N rows) gives three stacks (N, nv, nv).
    - Derivatives with respect to ``q`` are taken in the tangent space, Pinocchio's
      convention: column ``j`` of ``∂f/∂q`` is ``d/dε f(integrate(q, ε e_j))`` at ε = 0,
      with ``integrate`` as :meth:`robodyn.Robot.integrate`. For joints that is the plain
      partial derivative; for a floating base its six columns are the derivatives along
      the base's linear and angular displacements in the base frame (the components of
      its twist), not along the seven numbers of the position and quaternion.
    - Mimic joints go through the robot with every joint free
      (:mod:`robodyn.dynamics.mimic`): ``τ = Sᵀ τ_full(Q q + offset, S v, S a)`` is exact
      and linear in the map, so ``∂τ/∂q = Sᵀ (∂τ_full/∂q_full) S`` (likewise for ``v``,
      and ``∂τ/∂a = Sᵀ M_full S = M``). Forward dynamics is then derived from the reduced
      equations: with ``q̈`` the acceleration at ``(q, v, τ)``, ``∂q̈/∂q = −M⁻¹ ∂τ/∂q``
      and ``∂q̈/∂v = −M⁻¹ ∂τ/∂v`` (both at ``a = q̈``) and ``∂q̈/∂τ = M⁻¹`` (not
      ``Sᵀ (∂q̈_full) S``, which would be wrong).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from robodyn.dynamics.handle import PINOCCHIO_ERRORS, QUATERNION_TOLERANCE, ModelHandle
from robodyn.exceptions import NonFiniteResultError, SingularMassMatrixError

#: Three derivative matrices: (nv, nv) each for one state, (N, nv, nv) each for a batch.
Derivatives = tuple[np.ndarray, np.ndarray, np.ndarray]
_isfinite = math.isfinite
_FLOAT = np.dtype(np.float64)


def inverse_dynamics_derivatives(handle: ModelHandle, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
    """``(∂τ/∂q, ∂τ/∂v, ∂τ/∂a)`` of ``τ = M(q) a + C(q, v) v + G(q)``; ``∂τ/∂a = M(q)``.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).
        a: Acceleration, shape (nv,) or (N, nv).

    Returns:
        Three arrays of shape (nv, nv) or (N, nv, nv): row ``i`` is torque ``i`` in [N m] /
        [N], column ``j`` per unit of coordinate ``j`` ([rad], [m]; per [rad/s], [m/s]
        for ``v``; per [rad/s²], [m/s²] for ``a``). ``q`` columns in the tangent space
        (module docstring).

    Raises:
        InputError: For arguments :meth:`ModelHandle.validate` refuses.
        NonFiniteResultError: For a non-finite result of finite inputs (an overflow).
    """
    return _evaluate(handle, "inverse dynamics derivatives", ("q", "v", "a"), rnea_derivatives(handle), q, v, a)


def forward_dynamics_derivatives(handle: ModelHandle, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> Derivatives:
    """``(∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ)`` of ``q̈ = M(q)⁻¹ (τ − C(q, v) v − G(q))``; ``∂q̈/∂τ = M(q)⁻¹``.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).
        tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

    Returns:
        Three arrays of shape (nv, nv) or (N, nv, nv): row ``i`` is acceleration ``i``,
        column ``j`` per unit of ``q_j``, ``v_j`` or ``τ_j``; ``q`` columns in the
        tangent space (module docstring). ``∂q̈/∂τ`` is symmetric.

    Raises:
        InputError: For arguments :meth:`ModelHandle.validate` refuses.
        SingularMassMatrixError: If ``M(q)`` is singular (massless moving bodies).
    """
    try:
        return _evaluate(handle, "forward dynamics derivatives", ("q", "v", "tau"), aba_derivatives(handle), q, v, tau)
    except NonFiniteResultError:  # finite inputs, non-finite derivatives: a singular M
        from robodyn.dynamics.kernels import massless_joints

        raise SingularMassMatrixError(handle.name, massless_joints(handle.model)) from None


def rnea_derivatives(handle: ModelHandle) -> Callable[[np.ndarray, np.ndarray, np.ndarray], Derivatives]:
    """The unchecked one-state function ``(q, v, a) -> (∂τ/∂q, ∂τ/∂v, M)`` of a handle
    (float64 1-D arrays of the right sizes).

    Args:
        handle: The robot's model handle.
    """
    mimic = handle.mimic
    if mimic is None:
        model = handle.model

        def derivatives(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
            # Pinocchio 4 returns its data's matrices (copied here), M with both triangles
            dq, dv, mass = pin.computeRNEADerivatives(model, handle.data, q, v, a)
            return dq.copy(), dv.copy(), mass.copy()

        return derivatives
    selection = mimic.selection

    def expanded(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        full = mimic.model
        dq, dv, mass = pin.computeRNEADerivatives(full, mimic.data, mimic.q(q), selection @ v, selection @ a)
        return selection.T @ dq @ selection, selection.T @ dv @ selection, selection.T @ mass @ selection

    return expanded


def aba_derivatives(handle: ModelHandle) -> Callable[[np.ndarray, np.ndarray, np.ndarray], Derivatives]:
    """The unchecked one-state function ``(q, v, τ) -> (∂q̈/∂q, ∂q̈/∂v, M⁻¹)`` of a handle.

    Pinocchio's ABA derivatives, or for mimic joints the reduced equations (module
    docstring): ``q̈`` by a linear solve, then ``−M⁻¹ ∂τ/∂(q, v)`` at ``a = q̈``.
    A singular ``M`` gives non-finite values.

    Args:
        handle: The robot's model handle.
    """
    if handle.mimic is None:
        model = handle.model

        def derivatives(q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> Derivatives:
            # Pinocchio 4 returns its data's matrices (copied here), M⁻¹ with both triangles
            dq, dv, inverse = pin.computeABADerivatives(model, handle.data, q, v, tau)
            return dq.copy(), dv.copy(), inverse.copy()

        return derivatives
    inverse_dynamics, forward = rnea_derivatives(handle), handle.kernels.a.single

    def reduced(q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> Derivatives:
        try:
            acceleration = forward(q, v, tau)
            dq, dv, mass = inverse_dynamics(q, v, acceleration)
            inverse = np.linalg.inv(mass)
        except (SingularMassMatrixError, np.linalg.LinAlgError):
            nan = np.full((handle.nv, handle.nv), np.nan)
            return nan, nan, nan
        inverse = 0.5 * (inverse + inverse.T)
        return -inverse @ dq, -inverse @ dv, inverse

    return reduced


def _evaluate(
    handle: ModelHandle,
    what: str,
    names: tuple[str, str, str],
    single: Callable[[np.ndarray, np.ndarray, np.ndarray], Derivatives],
    *values: np.ndarray,
) -> Derivatives:
    """Fast path (three float64 1-D arrays straight to Pinocchio, a finite result and ``q``
    and a unit quaternion accepted), else the checked path: one state, or a batch row by row.

    Raises:
        InputError: For arguments :meth:`ModelHandle.validate` refuses.
        NonFiniteResultError: For a non-finite result of finite inputs.
    """
    q, v, third = values
    arrays_1d = type(q) is np.ndarray and type(v) is np.ndarray and type(third) is np.ndarray
    if arrays_1d and q.ndim == v.ndim == third.ndim == 1 and q.dtype == v.dtype == third.dtype == _FLOAT:
        try:
            result = single(q, v, third)
            if _fine(handle, values, result):
                return result
        except PINOCCHIO_ERRORS:
            pass
    arrays, batch = handle.validate(**dict(zip(names, values, strict=True)))
    if not batch:
        result = single(*arrays)
    else:
        rows = [single(*row) for row in zip(*arrays, strict=True)]
        nv = handle.nv
        result = tuple(np.stack([row[k] for row in rows]) if rows else np.zeros((0, nv, nv)) for k in range(3))  # type: ignore[assignment]
    if not all(np.isfinite(part).all() for part in result):
        raise NonFiniteResultError(handle.name, what)
    return result


def _fine(handle: ModelHandle, values: tuple[np.ndarray, ...], result: Derivatives) -> bool:
    """Whether a fast-path result may be returned: finite, of finite inputs with a unit
    base quaternion (anything else goes through the checks, which name the argument).

    A NaN or inf anywhere makes a sum (the inputs) or a sum of squares (the results)
    non-finite; a finite sum that overflows only sends the caller to the exact checks.
    """
    if not _isfinite(sum(values[0].tolist()) + sum(values[1].tolist()) + sum(values[2].tolist())):
        return False
    for part in result:
        flat = part.ravel()
        if not _isfinite(flat.dot(flat)):
            return False
    if handle.floating_base:
        quaternion = values[0][3:7]
        return abs(quaternion.dot(quaternion) - 1.0) < QUATERNION_TOLERANCE
    return True


__all__ = ["Derivatives", "aba_derivatives", "forward_dynamics_derivatives", "inverse_dynamics_derivatives", "rnea_derivatives"]
