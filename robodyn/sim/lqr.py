"""Linear-quadratic regulation about an equilibrium (:class:`LQR`, re-exported by
:mod:`robodyn.sim.control`): the gain from the continuous or discrete Riccati equation of
the model's linearisation, underactuated robots included (``actuated=``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.linearize import StepIntegrator, actuation_matrix, linearize
from robodyn.sim.twin import compiled_model, law_refusal

if TYPE_CHECKING:
    from robodyn.compiled.controllers import CompiledLQR


@dataclass
class LQR:
    """Linear-quadratic regulator about an equilibrium: ``u = u_eq − K (x − x_eq)``.

    The gain comes from the continuous Riccati equation of the linearisation
    (:func:`robodyn.sim.linearize.linearize`, ``dt=None``) or, with ``dt``, from the
    discrete one of one integrator step (then simulate with ``hold=True`` and the same
    ``dt`` and ``integrator``: that is the system the gain was designed on). It minimises
    ``∫ (δxᵀ Q δx + δuᵀ R δu) dt`` (or the sum over steps), ``δx = (q − q_eq, v − v_eq)``.
    Torques are ``τ = S_act u``: unactuated joints (``actuated``) get zero torque.

    Attributes:
        model: The controller's model of the robot (fixed base).
        q_eq: Equilibrium configuration, shape (nq,).
        v_eq: Equilibrium velocity, shape (nv,): zeros (an equilibrium holds still).
        Q: State weight: a scalar, the diagonal (2 nv,) or a matrix (2 nv, 2 nv), per
            [rad²] / [m²] and [rad²/s²] / [m²/s²].
        R: Input weight: a scalar, (nu,) or (nu, nu), per [N² m²] / [N²].
        dt: Step in [s] for a discrete design; ``None``: continuous.
        actuated: Names of the actuated joints; ``None``: all.
        integrator: With ``dt``: the integrator the step is taken with.

    Raises:
        InputError: A floating base, an equilibrium the actuated joints cannot hold (with
            the torque missing), bad weights, or a linearisation no gain stabilises.
    """

    model: Robot
    q_eq: np.ndarray
    v_eq: np.ndarray
    Q: float | np.ndarray
    R: float | np.ndarray
    dt: float | None = None
    actuated: list[str] | None = None
    integrator: StepIntegrator = "rk4"
    #: LQR is designed about a fixed base's equilibrium.
    twin_fixed_base: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.gain, self.u_eq, self.actuation = lqr_gain(
            self.model, self.q_eq, self.v_eq, self.Q, self.R, dt=self.dt, actuated=self.actuated, integrator=self.integrator
        )
        self.x_eq = np.concatenate([np.asarray(self.q_eq, float), np.asarray(self.v_eq, float)])

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        error = np.concatenate([q, v]) - self.x_eq
        return self.actuation @ (self.u_eq - self.gain @ error)

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin (``None``: it has one)."""
        return law_refusal(self, LQR)

    def compiled(self) -> CompiledLQR:
        """The same law in C (:class:`~robodyn.compiled.controllers.CompiledLQR`)."""
        from robodyn.compiled.controllers import CompiledLQR

        return CompiledLQR(compiled_model(self.model, self.twin_refusal()), self.gain, self.u_eq, self.actuation, self.x_eq)


def lqr_gain(
    model: Robot,
    q_eq: np.ndarray,
    v_eq: np.ndarray,
    Q: float | np.ndarray,
    R: float | np.ndarray,
    *,
    dt: float | None = None,
    actuated: list[str] | None = None,
    integrator: StepIntegrator = "rk4",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The gain ``K`` (nu, 2 nv), the holding input ``u_eq`` (nu,) and ``S_act`` (nv, nu) of
    :class:`LQR` (its attributes are the arguments; same errors).

    Args:
        model: The controller's model of the robot (fixed base).
        q_eq: Equilibrium configuration, shape (nq,).
        v_eq: Equilibrium velocity, shape (nv,): zeros (an equilibrium holds still).
        Q: State weight: a scalar, the diagonal (2 nv,) or a matrix (2 nv, 2 nv), per [rad²] / [m²] and [rad²/s²] / [m²/s²].
        R: Input weight: a scalar, (nu,) or (nu, nu), per [N² m²] / [N²].
        dt: Step in [s] for a discrete design; ``None``: continuous.
        actuated: Names of the actuated joints; ``None``: all.
        integrator: With ``dt``: the integrator the step is taken with.
    """
    import scipy.linalg

    if model.floating_base:
        raise InputError("model", "a fixed-base robot (LQR about a floating base's pose is not supported)", "a floating base")
    (q_eq, v_eq), batch = model.validate(q=q_eq, v=v_eq)
    if batch or np.any(v_eq != 0.0):
        raise InputError("v_eq", f"{model.nv} zeros (an equilibrium holds still)", np.array2string(np.asarray(v_eq)))
    selection = actuation_matrix(model, actuated)
    holding = model.gravity(q_eq)
    u_eq = np.linalg.lstsq(selection, holding, rcond=None)[0]
    missing = holding - selection @ u_eq
    scale = max(1.0, np.abs(holding).max(), model.total_mass * float(np.linalg.norm(model.gravity_vector)))
    if np.abs(missing).max() > 1e-6 * scale:  # [N m] / [N]: a target typed to 8 digits holds
        unheld = ", ".join(f"{x:.3g}" for x in missing)
        raise InputError("q_eq", "an equilibrium the actuated joints can hold", f"gravity torques left unheld [{unheld}]")
    # designed on the rigid-body model, as every controller here (no friction compensated)
    A, B = linearize(model, q_eq, v_eq, holding, dt=dt, integrator=integrator, actuation=selection, joint_friction=False)
    weights = _weight(Q, 2 * model.nv, "Q"), _weight(R, selection.shape[1], "R")
    try:
        if dt is None:
            riccati = scipy.linalg.solve_continuous_are(A, B, *weights)
            gain = np.linalg.solve(weights[1], B.T @ riccati)
        else:
            riccati = scipy.linalg.solve_discrete_are(A, B, *weights)
            gain = np.linalg.solve(weights[1] + B.T @ riccati @ B, B.T @ riccati @ A)
    except (np.linalg.LinAlgError, ValueError) as error:
        raise InputError("Q, R", "weights for which the Riccati equation has a stabilising solution", str(error)) from None
    return gain, u_eq, selection


def _weight(value: float | np.ndarray, size: int, name: str) -> np.ndarray:
    """A weight matrix from a scalar, a diagonal (size,) or a matrix (size, size): symmetric,
    finite, positive semi-definite (``R``: definite)."""
    try:
        array = np.asarray(value, dtype=float) if not np.iscomplexobj(value) else np.array([])
    except (TypeError, ValueError):  # text: refused below
        array = np.array([])
    matrix = array * np.eye(size) if array.ndim == 0 else (np.diag(array) if array.shape == (size,) else array)
    smallest = np.linalg.eigvalsh(matrix)[0] if matrix.shape == (size, size) and np.isfinite(matrix).all() else -np.inf
    symmetric = matrix.shape == (size, size) and np.allclose(matrix, matrix.T)
    if not symmetric or smallest < 0 or (name == "R" and smallest <= 0):
        expected = "positive definite" if name == "R" else "positive semi-definite"
        raise InputError(
            name, f"a scalar, {size} diagonal values or a symmetric {expected} {size}x{size} matrix", f"shape {array.shape}"
        )
    return matrix
