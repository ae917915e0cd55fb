"""Joint-space PD gains scaled to each joint's inertia: the defaults that do not diverge.

Fixed gains (``kp = 100 N m/rad``, ``kd = 20 N m s/rad``) put a light joint's closed-loop
poles far out: a wrist with ``M_jj = 0.0046 kg m²`` gets ``kd / M_jj ≈ 4 300 /s``, beyond
what RK4 holds at a 1 ms step (``|λ| dt ≤ 2.8``). Scaled to the joint's inertia, every
joint gets the same critically damped response, ``ω = 10 rad/s``, whatever its mass.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.text import counted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError

#: The natural frequency [rad/s] of the default PD gains (critically damped).
PD_FREQUENCY = 10.0


def joint_inertia(robot: Robot, q: np.ndarray, driven: np.ndarray | None = None) -> np.ndarray:
    """Each joint's inertia at ``q``, in [kg m²] or [kg], shape (n,), the joints only; ``q``
    of shape (k, nq), several configurations: each joint's largest over them.

    What a driven joint's torque accelerates when the degrees of freedom no actuator drives
    give way: the diagonal of ``M_dd − M_du M_uu⁻¹ M_ud`` (a fixed base with every joint
    driven: the diagonal of ``M(q)``; a floating base: its six are not driven).

    Args:
        robot: The robot.
        q: Configuration(s), shape (nq,) or (k, nq).
        driven: Which degrees of freedom an actuator drives, shape (nv,); ``None``: every
            joint (not a floating base's six). An undriven joint's entry is its ``M_jj``.
    """
    mask = np.array([not dof.is_base for dof in robot.dofs]) if driven is None else np.asarray(driven, dtype=bool)
    rows = np.atleast_2d(np.asarray(q, dtype=float))
    return np.max([_diagonal(robot, row, mask) for row in rows], axis=0)


def _diagonal(robot: Robot, q: np.ndarray, driven: np.ndarray) -> np.ndarray:
    """The joints' inertias at one configuration (see :func:`joint_inertia`)."""
    mass = robot.mass_matrix(q)
    out, free = np.diag(mass).copy(), ~driven
    if free.any():
        coupling = mass[np.ix_(driven, free)]
        schur = mass[np.ix_(driven, driven)] - coupling @ np.linalg.solve(mass[np.ix_(free, free)], coupling.T)
        out[driven] = np.diag(schur)
    return out[6:] if robot.floating_base else out


def pd_gains(
    robot: Robot,
    q: np.ndarray,
    *,
    kp: float | list[float] | np.ndarray | None = None,
    kd: float | list[float] | np.ndarray | None = None,
    driven: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """PD gains per joint, in [N m/rad] and [N m s/rad] (prismatic: [N/m], [N s/m]), shape (n,)
    each (n: the joints, a floating base's six left out).

    Defaults: ``kp = ω² m`` and ``kd = 2 ω m`` with ``m`` :func:`joint_inertia` at ``q``
    and ``ω`` :data:`PD_FREQUENCY` (a critically damped 10 rad/s on every joint). A
    ``kp`` given without ``kd`` gets the critically damping ``kd = 2 √(kp m)``; a ``kd``
    given alone keeps the default ``kp``.

    Args:
        robot: The robot.
        q: The configuration the inertia is taken at, shape (nq,), or several, (k, nq):
            each joint's largest inertia over them (a run's start and target).
        kp: Stiffness: a scalar or one value a joint; ``None``: the default.
        kd: Damping: a scalar or one value a joint; ``None``: the default.
        driven: As for :func:`joint_inertia`.

    Raises:
        InputError: A gain that is not finite and ≥ 0, or of another size than the joints.
    """
    inertia = joint_inertia(robot, q, driven)
    stiffness = PD_FREQUENCY**2 * inertia if kp is None else gain_values(kp, "kp", inertia.size)
    if kd is not None:
        damping = gain_values(kd, "kd", inertia.size)
    elif kp is None:
        damping = 2.0 * PD_FREQUENCY * inertia
    else:
        damping = 2.0 * np.sqrt(stiffness * np.maximum(inertia, 0.0))
    return stiffness, damping


def computed_torque_gains(
    size: int, *, kp: float | list[float] | np.ndarray | None = None, kd: float | list[float] | np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Computed torque's gains in [1/s²] and [1/s], shape (size,) each: as given (checked
    as :func:`gain_values`), else 400 and 40 (a critically damped 20 rad/s: the law
    divides by the inertia itself, so one pair suits every joint)."""
    stiffness = np.full(size, 400.0) if kp is None else gain_values(kp, "kp", size)
    return stiffness, (np.full(size, 40.0) if kd is None else gain_values(kd, "kd", size))


def gain_values(value: float | list[float] | np.ndarray, name: str, size: int) -> np.ndarray:
    """A gain as one value a joint: a scalar broadcast, or ``size`` values; finite and ≥ 0."""
    try:
        array = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        array = np.array([np.nan])
    if array.size == 1:
        array = np.full(size, array[0])
    if array.size != size or not np.isfinite(array).all() or (array < 0).any():
        got = counted(array.size, "value") if array.size != size else np.array2string(array, precision=4)
        raise InputError(name, f"one finite value >= 0, or {size} (one a joint)", got)
    return array


#: The largest joint acceleration [rad/s²] / [m/s²] the default LQR weights budget for.
LQR_ACCELERATION = 100.0


def lqr_weights(robot: Robot, q_eq: np.ndarray, actuated: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The LQR weights ``simulate --controller lqr`` uses (Bryson's rule): ``Q`` with
    1 / (0.3 rad)² per position and 1 / (1 rad/s)² per velocity (prismatic: 0.03 m,
    0.1 m/s); ``R`` with 1 / u_j² per actuated joint, ``u_j`` the smaller of its effort
    limit and ``M_jj(q_eq)`` × :data:`LQR_ACCELERATION` (so light distal joints are not
    given gains too stiff for a millisecond step).
    """
    positions = [1 / 0.03**2 if dof.linear else 1 / 0.3**2 for dof in robot.dofs]
    velocities = [100.0 if dof.linear else 1.0 for dof in robot.dofs]
    chosen = robot.joint_names if actuated is None else actuated
    inertia = np.diag(robot.mass_matrix(q_eq))
    scales = [
        min(
            dof.effort_limit if np.isfinite(dof.effort_limit) and dof.effort_limit > 0 else np.inf,
            inertia[dof.index] * LQR_ACCELERATION,
        )
        for dof in robot.dofs
        if dof.joint in chosen
    ]
    return np.diag(positions + velocities), np.diag(1.0 / np.square(scales))
