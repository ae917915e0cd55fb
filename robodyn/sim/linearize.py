"""Linearisation of a robot's dynamics about a state: ``(A, B)`` in continuous time, or
the exact Jacobians of one step of robodyn's integrators.

The state is ``x = (q, v)`` and the input ``u`` with joint torques ``τ = S_act u``
(``S_act``, shape (nv, nu), the actuation matrix: the identity by default, or the columns
of the actuated joints, :func:`actuation_matrix`).

- Continuous time (``dt=None``): ``ẋ = f(x, u)``, ``A = ∂f/∂x = [[A_qq, I], [∂q̈/∂q, ∂q̈/∂v]]``
  and ``B = [[0], [M⁻¹ S_act]]``, with ``A_qq = 0`` for a fixed base.
- Discrete time (``dt`` in [s]): ``x⁺ = step(x, u)``, one step of
  :func:`robodyn.simulate` with the torque held over the step (``"rk4"`` or
  ``"semi-implicit-euler"``, stage by stage as :mod:`robodyn.sim.simulation` does it),
  and ``(A, B)`` its exact Jacobians: the chain rule through every stage with the
  analytical derivatives of forward dynamics
  (:meth:`robodyn.Robot.forward_dynamics_derivatives`), not finite differences. A
  controller designed on them is designed on the simulator that runs it.

A batch (2-D ``q``, ``v``, ``tau``: one state a row, N rows) gives stacks ``A`` (N, 2 nv,
2 nv) and ``B`` (N, 2 nv, nu), each row what its single call gives: the derivatives of the
whole batch in one call of :meth:`robodyn.Robot.forward_dynamics_derivatives` per stage (one
in continuous time, four for an RK4 step), the chain rule on stacks.

Floating base: ``q`` perturbations are in the tangent space (Pinocchio's convention,
``q ⊕ δq = robot.integrate(q, δq)``: the base's six entries are its displacement in the
base frame, linear then angular), so ``A`` is (2 nv, 2 nv), not (nq + nv)². In continuous
time the base's ``A_qq`` block is then ``−ad(v_base)`` (the twist's motion action: a
tangent vector carried along a moving base), zero at rest. In discrete time, ``δq⁺`` is
in the tangent space at ``q⁺``.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from robodyn.common.text import printable, quoted
from robodyn.compiled.loop_rules import INTEGRATORS, Integrator, check_integrator
from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.joint_dynamics import friction_torque
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError

#: The integrators of :func:`robodyn.simulate` (:mod:`robodyn.compiled.loop_rules`, the
#: rules both simulation loops share).
StepIntegrator = Integrator
STEP_INTEGRATORS: tuple[StepIntegrator, ...] = INTEGRATORS


@dataclass(frozen=True)
class Linearization:
    """A linearisation ``δẋ = A δx + B δu`` (continuous) or ``δx⁺ = A δx + B δu`` (one step).

    Attributes:
        robot: The robot's name.
        dofs: Its degrees of freedom (names, units), length nv.
        q: Configuration, shape (nq,); ``v``: velocity, (nv,); ``tau``: torques, (nv,), in
            [N m] / [N] (the holding torque when none was given).
        dt: The step in [s], or ``None`` for continuous time.
        integrator: The step's integrator, or ``None`` for continuous time.
        A: Shape (2 nv, 2 nv): rows and columns ``(δq, δv)``, ``δq`` in the tangent space.
        B: Shape (2 nv, nu): columns per unit of input, [N m] or [N].
        actuation: ``S_act``, shape (nv, nu).
    """

    robot: str
    dofs: tuple[Dof, ...]
    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    dt: float | None
    integrator: StepIntegrator | None
    A: np.ndarray
    B: np.ndarray
    actuation: np.ndarray

    @property
    def inputs(self) -> tuple[str, ...]:
        """A name per input (column of ``B``): the degree of freedom its actuation column
        selects, else ``u<k>``."""
        names = []
        for k, column in enumerate(self.actuation.T):
            hits = np.flatnonzero(column)
            names.append(self.dofs[int(hits[0])].name if hits.size == 1 and column[hits[0]] == 1.0 else f"u{k}")
        return tuple(names)

    def state_names(self) -> list[str]:
        """Names of the rows of ``A`` and ``B``: ``q[<dof>]`` then ``v[<dof>]``."""
        return [f"q[{dof.name}]" for dof in self.dofs] + [f"v[{dof.name}]" for dof in self.dofs]

    def units(self) -> dict[str, Any]:
        """Units of the state and of the input, by entry."""
        return {
            "q": [dof.position_unit for dof in self.dofs],
            "v": [dof.velocity_unit for dof in self.dofs],
            "u": [_input_unit(self.dofs, column) for column in self.actuation.T],
            "A": "SI: entry (i, j) in units of x_i per unit of x_j" + ("" if self.dt is not None else " per second"),
            "B": "SI: entry (i, k) in units of x_i per unit of u_k" + ("" if self.dt is not None else " per second"),
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (the ``robodyn linearize --json`` output)."""
        return {
            "robot": self.robot,
            "time": "continuous" if self.dt is None else "discrete",
            "dt": self.dt,
            "integrator": self.integrator,
            "state": self.state_names(),
            "inputs": list(self.inputs),
            "units": self.units(),
            "tangent_space": "q perturbations along robot.integrate (a floating base: base-frame displacement)",
            "q": self.q.tolist(),
            "v": self.v.tolist(),
            "tau": self.tau.tolist(),
            "A": self.A.tolist(),
            "B": self.B.tolist(),
        }

    def text(self, *, precision: int = 6) -> str:
        """Readable text: the state, the matrices with their row and column names.

        Args:
            precision: Significant digits of each number.
        """
        if self.dt is None:
            head = f"{self.robot}: continuous time, d(dx)/dt = A dx + B du"
        else:
            head = f"{self.robot}: one {self.integrator} step of dt = {self.dt:g} s, dx+ = A dx + B du"
        names = self.state_names()
        lines = [head, "state x = (q, v) in [rad] [m] and [rad/s] [m/s], input u in [N m] [N]"]
        lines += [f"tau (holding or given): {' '.join(f'{x:.{precision}g}' for x in self.tau)}", "", "A:"]
        lines += _rows(names, self.A, precision)
        lines += ["", f"B (columns: {', '.join(self.inputs)}):"]
        lines += _rows(names, self.B, precision)
        return "\n".join(printable(line) for line in lines)


def _real_array(value: Any) -> np.ndarray:
    """``value`` as a float array, or an empty one for anything not real numbers (complex
    values, text), for the caller's check to refuse."""
    if np.iscomplexobj(value):
        return np.array([])
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return np.array([])


def _input_unit(dofs: tuple[Dof, ...], column: np.ndarray) -> str:
    """The unit of an input: its degrees of freedom's effort unit, or "SI" when they differ."""
    units = {dofs[int(k)].effort_unit for k in np.flatnonzero(column)}
    return units.pop() if len(units) == 1 else "SI (N m and N)"


def _rows(names: list[str], matrix: np.ndarray, precision: int) -> list[str]:
    width = max(len(name) for name in names)
    return [
        f"  {name:{width}s} [" + " ".join(f"{x:{precision + 7}.{precision}g}" for x in row) + " ]"
        for name, row in zip(names, matrix, strict=True)
    ]


def actuation_matrix(robot: Robot, actuated: Sequence[str] | None) -> np.ndarray:
    """``S_act``, shape (nv, nu): one column a degree of freedom of the ``actuated`` joints
    (in the robot's order), or the identity for ``None``.

    Args:
        robot: The robot.
        actuated: Names of the actuated joints (one name as a string too); ``None``: all.

    Raises:
        InputError: For an unknown joint name, a repeated one or none at all.
    """
    if actuated is None:
        return np.eye(robot.nv)
    names = [actuated] if isinstance(actuated, str) else list(actuated)
    unknown = [name for name in names if name not in robot.joint_names]
    if unknown or not names or len(set(names)) != len(names):
        received = f"unknown {unknown}" if unknown else repr(names)
        raise InputError("actuated", f"distinct joint names of {robot.name} ({', '.join(robot.joint_names)})", received)
    columns = [dof.index for dof in robot.dofs if dof.joint in names]
    return np.eye(robot.nv)[:, columns]


def linearize(
    robot: Robot,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray | None = None,
    *,
    dt: float | None = None,
    integrator: StepIntegrator = "rk4",
    actuation: np.ndarray | None = None,
    joint_friction: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of the dynamics about ``(q, v, tau)``: continuous, or one step of ``dt``.

    Args:
        robot: The robot.
        q: Configuration, shape (nq,), or (N, nq): a batch, one state a row.
        v: Velocity, shape (nv,) or (N, nv).
        tau: Torques in [N m] / [N], shape (nv,) or (N, nv); ``None``: the torque that
            holds ``(q, v)`` at zero acceleration, ``C(q, v) v + G(q)``.
        dt: Step in [s] for the Jacobians of one integrator step; ``None``: continuous time.
        integrator: With ``dt``: ``"rk4"`` or ``"semi-implicit-euler"`` (as :func:`robodyn.simulate`).
        actuation: ``S_act`` of shape (nv, nu), torques ``τ = S_act u``; default the identity.
        joint_friction: Include the joints' damping and Coulomb friction, as
            :func:`robodyn.simulate` does by default: the viscous torque ``−b v`` exactly
            (``∂q̈/∂v`` gets ``−M⁻¹ diag(b)``) and a sliding joint's ``−f sign(v)`` (constant
            near the state). A joint with Coulomb friction at rest is refused (stiction is not
            differentiable there); ``False`` linearizes the rigid-body dynamics.

    Returns:
        ``A`` of shape (2 nv, 2 nv) and ``B`` of shape (2 nv, nu), or stacks (N, 2 nv, 2 nv)
        and (N, 2 nv, nu) for a batch (module docstring: conventions, the floating base's
        tangent space).

    Raises:
        InputError: For states that are not valid (or mix 1-D and 2-D), a bad step,
            integrator or actuation matrix.
        SingularMassMatrixError: If ``M(q)`` is singular (at any row of a batch).
    """
    _, _, A, B = _matrices(robot, q, v, tau, dt, integrator, actuation, joint_friction, batch_ok=True)
    return A, B


def linearization(
    robot: Robot,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray | None = None,
    *,
    dt: float | None = None,
    integrator: StepIntegrator = "rk4",
    actuation: np.ndarray | None = None,
    joint_friction: bool = True,
) -> Linearization:
    """:func:`linearize` of one state with the state, names and units (a :class:`Linearization`)."""
    (q, v, tau), selection, A, B = _matrices(robot, q, v, tau, dt, integrator, actuation, joint_friction, batch_ok=False)
    return Linearization(
        robot.name, robot.dofs, q, v, tau, None if dt is None else float(dt),
        None if dt is None else integrator, A, B, selection,
    )  # fmt: skip


def _matrices(
    robot: Robot,
    q: Any,
    v: Any,
    tau: Any,
    dt: float | None,
    integrator: str,
    actuation: Any,
    joint_friction: bool,
    *,
    batch_ok: bool,
) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """The checked state ``(q, v, tau)``, the actuation matrix and ``(A, B)`` (stacks for a
    batch, when ``batch_ok``)."""
    q, v, tau = _state(robot, q, v, tau, batch_ok)
    friction = _joint_friction(robot, v, bool(joint_friction))
    selection = _actuation(robot, actuation)
    if dt is not None and not (isinstance(dt, numbers.Real) and not isinstance(dt, bool) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", "a finite step > 0 in [s] (or None for continuous time)", repr(dt))
    check_integrator(integrator)
    if dt is None:
        A, B = _continuous(robot, q, v, tau, selection, friction)
    else:
        A, B = _Step(robot, tau, selection, friction).jacobians(q, v, float(dt), integrator)
    return (q, v, tau), selection, A, B


def _state(robot: Robot, q: Any, v: Any, tau: Any, batch_ok: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One checked state (or, ``batch_ok``, a batch); the holding torque ``C v + G`` for ``tau=None``."""
    named = {"q": q, "v": v} if tau is None else {"q": q, "v": v, "tau": tau}
    arrays, batch = robot.validate(**named)
    if batch and not batch_ok:
        raise InputError("q", "one state (1-D arrays): a linearisation is about one state", f"shape {arrays[0].shape}")
    if tau is None:
        arrays.append(_by_row(robot.nonlinear_effects, arrays[1].shape, arrays[0], arrays[1]))
    return arrays[0], arrays[1], arrays[2]


def _joint_friction(robot: Robot, v: np.ndarray, on: bool) -> tuple[np.ndarray, np.ndarray]:
    """The viscous ``b`` and Coulomb ``f`` (length nv) the linearisation includes: the joints'
    own (``on``), else zeros.

    Raises:
        InputError: If, ``on``, a joint with Coulomb friction does not move at ``v`` (naming them).
    """
    if not on:
        return np.zeros(robot.nv), np.zeros(robot.nv)
    stuck = [dof.name for dof in robot.dofs if dof.friction > 0 and (v[..., dof.index] == 0).any()]
    if stuck:
        listed = ", ".join(quoted(name) for name in stuck[:8]) + (", …" if len(stuck) > 8 else "")
        raise InputError(
            "joint_friction",
            "False to linearize at rest joints with Coulomb friction (stiction is not differentiable there)",
            f"True with {listed} at rest",
        )
    return robot.joint_damping, robot.joint_friction


def _actuation(robot: Robot, actuation: Any) -> np.ndarray:
    """The actuation matrix, checked: (nv, nu) finite, nu ≥ 1; the identity for ``None``."""
    if actuation is None:
        return np.eye(robot.nv)
    matrix = _real_array(actuation)
    if matrix.ndim != 2 or matrix.shape[0] != robot.nv or matrix.shape[1] < 1 or not np.isfinite(matrix).all():
        raise InputError("actuation", f"a finite matrix of shape ({robot.nv}, nu), nu >= 1", f"shape {matrix.shape}")
    return matrix


def _continuous(
    robot: Robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray, selection: np.ndarray, friction: tuple[np.ndarray, np.ndarray]
):
    """Continuous-time ``(A, B)`` (``friction``: the joints' ``(b, f)`` included); stacks
    for a batch (one derivative call for all of it)."""
    nv = robot.nv
    dq, dv, inverse = robot.forward_dynamics_derivatives(q, v, tau + friction_torque(*friction, v))
    dv = dv - inverse * friction[0]
    velocity_block = np.zeros(dq.shape)
    if robot.floating_base:  # the tangent space moves with the base: −ad(v_base)
        actions = [-pin.Motion(row[:6]).action for row in v.reshape(-1, nv)]
        velocity_block[..., :6, :6] = np.reshape(actions, (*v.shape[:-1], 6, 6))
    top = np.concatenate([velocity_block, np.broadcast_to(np.eye(nv), dq.shape)], axis=-1)
    A = np.concatenate([top, np.concatenate([dq, dv], axis=-1)], axis=-2)
    B = np.concatenate([np.zeros((*dq.shape[:-1], selection.shape[1])), inverse @ selection], axis=-2)
    return A, B


class _Step:
    """One integrator step and the Jacobians of its quantities with respect to
    ``z = (δq, δv, δu)`` (each a matrix with 2 nv + nu columns), stage by stage as
    :mod:`robodyn.sim.simulation` computes the step (torque held over the step)."""

    def __init__(self, robot: Robot, tau: np.ndarray, selection: np.ndarray, friction: tuple[np.ndarray, np.ndarray]) -> None:
        self.robot, self.tau, nv, nu = robot, tau, robot.nv, selection.shape[1]
        self.friction = friction  # the joints' (b, f) included
        self.dq0 = np.hstack([np.eye(nv), np.zeros((nv, nv + nu))])
        self.dv0 = np.hstack([np.zeros((nv, nv)), np.eye(nv), np.zeros((nv, nu))])
        self.dtau = np.hstack([np.zeros((nv, 2 * nv)), selection])

    def configuration(self, q: np.ndarray, w: np.ndarray, dw: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
        """``q ⊕ h w`` (the step's start ``q``) and its Jacobian, in the tangent space there."""
        robot = self.robot
        if not robot.floating_base:
            return q + h * w, self.dq0 + h * dw
        step = h * w
        by_q, by_step = (
            _by_row(lambda x, y, a=argument: pin.dIntegrate(robot.model, x, y, a), (*q.shape[:-1], robot.nv, robot.nv), q, step)
            for argument in (pin.ArgumentPosition.ARG0, pin.ArgumentPosition.ARG1)
        )
        return _by_row(robot.integrate, q.shape, q, step), by_q @ self.dq0 + h * by_step @ dw

    def acceleration(self, q: np.ndarray, dq: np.ndarray, v: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Forward dynamics at a stage and its Jacobian by the chain rule."""
        robot, friction = self.robot, self.friction
        tau = self.tau + friction_torque(*friction, v)
        by_q, by_v, inverse = robot.forward_dynamics_derivatives(q, v, tau)
        by_v = by_v - inverse * friction[0]
        return _by_row(robot.forward_dynamics, v.shape, q, v, tau), by_q @ dq + by_v @ dv + inverse @ self.dtau

    def jacobians(self, q: np.ndarray, v: np.ndarray, dt: float, integrator: str) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` of one step of ``dt`` from ``(q, v)``."""
        dq0, dv0, nv = self.dq0, self.dv0, self.robot.nv
        a1, da1 = self.acceleration(q, dq0, v, dv0)
        if integrator == "semi-implicit-euler":
            v_next, dv_next = v + dt * a1, dv0 + dt * da1
            _, dq_next = self.configuration(q, v_next, dv_next, dt)
        else:
            half, sixth = 0.5 * dt, dt / 6.0
            v2, dv2 = v + half * a1, dv0 + half * da1
            a2, da2 = self.acceleration(*self.configuration(q, v, dv0, half), v2, dv2)
            v3, dv3 = v + half * a2, dv0 + half * da2
            a3, da3 = self.acceleration(*self.configuration(q, v2, dv2, half), v3, dv3)
            v4, dv4 = v + dt * a3, dv0 + dt * da3
            _, da4 = self.acceleration(*self.configuration(q, v3, dv3, dt), v4, dv4)
            mean, dmean = v + v4 + 2.0 * (v2 + v3), dv0 + dv4 + 2.0 * (dv2 + dv3)
            _, dq_next = self.configuration(q, mean, dmean, sixth)
            dv_next = dv0 + sixth * (da1 + da4 + 2.0 * (da2 + da3))
        jacobian = np.concatenate([dq_next, dv_next], axis=-2)
        return jacobian[..., : 2 * nv], jacobian[..., 2 * nv :]


def _by_row(function: Any, shape: tuple[int, ...], *states: np.ndarray) -> np.ndarray:
    """``function`` of one state, or of each row of a batch stacked to ``shape`` (N may be 0):
    every row its single call's (a batch call may differ from it in the last bits)."""
    if states[0].ndim == 1:
        return function(*states)
    return np.array([function(*row) for row in zip(*states, strict=True)]).reshape(shape)


__all__ = ["STEP_INTEGRATORS", "Linearization", "StepIntegrator", "actuation_matrix", "linearization", "linearize"]
