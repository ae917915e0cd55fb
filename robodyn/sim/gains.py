"""Joint-space PD gains scaled to each joint's inertia: the defaults that do not diverge.

Fixed gains (``kp = 100 N m/rad``, ``kd = 20 N m s/rad``) put a light joint's closed-loop
poles far out: a wrist with ``M_jj = 0.0046 kg m²`` gets ``kd / M_jj ≈ 4 300 /s``, beyond
what RK4 holds at a 1 ms step (``|λ| dt ≤ 2.8``). Scaled to the joint's inertia, every
joint gets the same critically damped response, ``ω = 10 rad/s``, whatever its mass.

A floating robot on the ground carries its weight through its joints: the inertia rule
alone (its legs' inertias with the base free, grams times centimetres squared) lets solo12
fold flat. :func:`load_gains` adds the load each joint carries at the target pose
(:func:`joint_loads`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robodyn.common.text import counted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_checks import start_above
from robodyn.sim.control import joint_target
from robodyn.sim.ground import ContactPoint, Ground, contact_points

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
    divides by the inertia itself, so one pair suits every joint).

    Args:
        size: Number of joints.
        kp: Stiffness in [1/s²]: one value or one a joint (``None``: 400).
        kd: Damping in [1/s]: one value or one a joint (``None``: 40).
    """
    stiffness = np.full(size, 400.0) if kp is None else gain_values(kp, "kp", size)
    return stiffness, (np.full(size, 40.0) if kd is None else gain_values(kd, "kd", size))


def gain_values(value: float | list[float] | np.ndarray, name: str, size: int) -> np.ndarray:
    """A gain as one value a joint: a scalar broadcast, or ``size`` values; finite and ≥ 0.

    Args:
        value: A scalar or one value a joint.
        name: The parameter's name, for the error.
        size: Number of joints.
    """
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

    Args:
        robot: The controlled robot (fixed base).
        q_eq: Equilibrium configuration, shape (nq,), in [rad] / [m].
        actuated: Names of the actuated joints; ``None``: all.
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


#: The joint angle [rad] (or travel [m]) a joint gives under its full load moment
#: (:func:`load_gains`).
LOAD_GIVE = 0.05


def joint_loads(robot: Robot, q: np.ndarray, jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The load moment and the carried inertia of each joint of a floating robot standing
    at ``q`` on the contact points of ``jacobian`` (3k, nv, rows of a contact in any
    orthonormal axes), shapes (n,) each (the joints).

    The contact forces ``f`` that hold the robot still are the minimum-norm solution of
    the base's rows of ``G(q) = Jᵀ f``; joint ``j`` carries the load moment
    ``L_j = Σ_c ‖f_c‖ ‖∂p_c/∂q_j‖`` (each force times its lever about the joint, ``‖J_c,j‖``
    the distance of the contact from the joint's axis) in [N m] ([N]) and the inertia
    ``Σ_c ‖f_c‖ / g ‖∂p_c/∂q_j‖²`` in [kg m²] ([kg]) of the weight it lifts.

    Args:
        robot: A floating robot.
        q: Its configuration, shape (nq,).
        jacobian: The contact points' Jacobians, shape (3k, nv).
    """
    gravity = robot.gravity(q)
    forces = np.linalg.lstsq(jacobian[:, :6].T, gravity[:6], rcond=None)[0].reshape(-1, 3)
    magnitude = np.linalg.norm(forces, axis=1)
    levers = np.linalg.norm(jacobian[:, 6:].reshape(len(magnitude), 3, -1), axis=1)  # (k, n)
    g = max(float(np.linalg.norm(robot.model.gravity.linear)), 1e-300)
    return magnitude @ levers, (magnitude / g) @ levers**2


def load_gains(
    robot: Robot, q: np.ndarray, jacobian: np.ndarray, driven: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Default PD gains of a floating robot standing at ``q`` on the contacts of
    ``jacobian`` (3k, nv), shape (n,) each (the joints).

    ``kp = ω² m + L / θ``: the inertia rule (:func:`pd_gains`, ``m`` the joint's inertia
    with the base free) plus the load moment ``L`` (:func:`joint_loads`) over
    :data:`LOAD_GIVE` ``θ``: a joint gives ``θ`` under its full load moment, and the torque
    it must hold is at most ``L``, so it sags at most ``θ``. ``kd = 2 √(kp m)``: critical
    on the joint's own inertia, so a leg in the air stays stable at a millisecond step
    (damped for the carried weight, a leg's ``kd / m`` would exceed ``2 / dt``).

    Args:
        robot: A floating robot.
        q: Its configuration, shape (nq,).
        jacobian: The contact points' Jacobians, shape (3k, nv).
        driven: Which degrees of freedom an actuator drives, shape (nv,) (as
            :func:`joint_inertia`); ``None``: every joint.
    """
    inertia = joint_inertia(robot, q, driven)
    stiffness = PD_FREQUENCY**2 * inertia + joint_loads(robot, q, jacobian)[0] / LOAD_GIVE
    return stiffness, 2.0 * np.sqrt(stiffness * inertia)


def pd_defaults(
    robot: Robot, controller: str, target: list[float] | None, start: np.ndarray, gains: dict,
    ground: Ground | None, contacts: str | Sequence[str | ContactPoint],
) -> tuple[list[float] | None, dict]:  # fmt: skip
    """The pd controller's defaults: without a ``target``, the start's joints (held); a
    floating robot on a ``ground`` with neither ``kp`` nor ``kd`` in ``gains``: the gains
    of :func:`load_gains` at the target pose set on the ground, on its contact points that
    touch it (those within 1 mm of the lowest). Other controllers: unchanged.

    Args:
        robot: The plant.
        controller: The controller's name; only ``"pd"`` has these defaults.
        target: The joint target, one value a joint, or ``None``.
        start: The start configuration, shape (nq,).
        gains: The gains given (``kp``, ``kd``; ``None`` values: not given).
        ground: The ground, or ``None``.
        contacts: The contact points asked for (as ``simulate``'s ``contacts``).
    """
    if controller != "pd":
        return target, gains
    if target is None:
        target = list(start[7:] if robot.floating_base else start)
    if ground is None or not robot.floating_base or gains.get("kp") is not None or gains.get("kd") is not None:
        return target, gains
    goal = np.array(start, dtype=float)
    goal[7:] = joint_target(robot, target, "pd")
    standing = start_above(robot, goal, ground, contacts, clearance=0.0)[0]
    gaps, jacobian = contact_kinematics(robot, standing, ground, contact_points(robot, contacts).points)
    support = np.repeat(gaps <= gaps.min() + 1e-3, 3)
    kp, kd = load_gains(robot, standing, jacobian[support])
    return target, {**gains, "kp": kp, "kd": kd}
