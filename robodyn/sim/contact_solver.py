"""The cone complementarity problem of one contact step: Pinocchio's ADMM, then a polish.

For ``k`` contacts with the Delassus matrix ``A = J M⁻¹ Jᵀ`` (3k, 3k) and the free
velocity ``c`` (3k,) (each contact's rows ``t₁, t₂, n``), find the impulses ``p`` with
``pᵢ ∈ K_μ``, ``ûᵢ = uᵢ + μ ‖u_{t,i}‖ n ∈ K_μ*``, ``pᵢ · ûᵢ = 0`` where ``u = A p + c``
(:mod:`robodyn.sim.contact`).

1. **Pinocchio's ADMM** (``ADMMConstraintSolver``, ``solve_ncp``: the De Saxcé
   correction, so the true Coulomb problem rather than its convex relaxation) over
   ``DelassusOperatorDense(A)``, warm-started with the previous step's impulses. On a
   redundant contact set (a box's 4 resting corners have 12 rows for 6 degrees of freedom)
   its iterations converge slowly in the directions ``A`` does not see. ADMM runs only when
   the previous step's contact modes, polished (below), no longer solve the problem.
2. **Polish** (as OSQP polishes a QP): ADMM's answer names each contact *open* (no
   force), *sticking* (``u = 0``) or *slipping* (``u_n = 0``, ``p_t = −μ p_n s`` along its
   slip direction ``s``); those equalities are solved exactly (least-norm, the
   constraints layer's rule for redundant rows) and the result kept only when it is a
   solution: every impulse in its cone, every open contact separating, every slip
   continuing along ``s`` (to :data:`POLISH_TOLERANCE`). Otherwise ADMM's answer stands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robodyn.exceptions import InputError

#: Relative tolerance of the polish's checks (cone, separation, slip direction).
POLISH_TOLERANCE = 1e-9


@dataclass(frozen=True)
class ContactSettings:
    """How a contact step is solved.

    Attributes:
        baumgarte: Fraction ``β`` of a penetration removed per step, in (0, 1].
        tolerance: ADMM's absolute and relative feasibility and complementarity tolerance.
        max_iterations: Most ADMM iterations a step.
        polish: Whether ADMM's answer is polished (module docstring).
    """

    baumgarte: float = 0.2
    tolerance: float = 1e-10
    max_iterations: int = 500
    polish: bool = True

    def __post_init__(self) -> None:
        if not (isinstance(self.baumgarte, int | float) and 0 < self.baumgarte <= 1):
            raise InputError("baumgarte", "a fraction in (0, 1]", repr(self.baumgarte))
        if not (isinstance(self.tolerance, int | float) and math.isfinite(self.tolerance) and self.tolerance > 0):
            raise InputError("tolerance", "a finite tolerance > 0", repr(self.tolerance))
        if not (isinstance(self.max_iterations, int) and self.max_iterations > 0):
            raise InputError("max_iterations", "an integer > 0", repr(self.max_iterations))


class _Workspace:
    """Pinocchio's ADMM solver and the cones of ``k`` contacts of friction ``μ`` (reused)."""

    def __init__(self, count: int, friction: float, settings: ContactSettings):
        empty = pin.Model()
        self.models, self.datas = pin.StdVec_ConstraintModel(), pin.StdVec_ConstraintData()
        for _ in range(count):
            cone = pin.PointContactConstraintModel(empty)
            cone.setFriction(friction)
            self.models.append(cone)
            self.datas.append(self.models[-1].createData())
        self.solver, self.result = pin.ADMMConstraintSolver(3 * count), pin.ADMMSolverResult()
        self.settings = pin.ADMMSolverSettings()
        self.settings.max_iterations = settings.max_iterations
        for name in ("absolute_feasibility_tol", "absolute_complementarity_tol"):
            setattr(self.settings, name, settings.tolerance)
        for name in ("relative_feasibility_tol", "relative_complementarity_tol"):
            setattr(self.settings, name, settings.tolerance)


_WORKSPACES: dict[tuple[int, float, ContactSettings], _Workspace] = {}


def solve_impulses(
    delassus: np.ndarray, velocity: np.ndarray, friction: float, settings: ContactSettings, guess: np.ndarray | None = None
) -> tuple[np.ndarray, int, bool]:
    """The impulses ``p`` (3k,) of the cone complementarity problem ``u = A p + c``
    (module docstring), with ADMM's iterations and whether it converged."""
    count = len(velocity) // 3
    if settings.polish and guess is not None and count:  # the previous step's modes may still hold: no ADMM
        kept = polish(delassus, velocity, friction, np.asarray(guess, dtype=float).reshape(-1))
        if kept is not None:
            return kept, 0, True
    key = (count, friction, settings)
    if key not in _WORKSPACES:
        _WORKSPACES[key] = _Workspace(count, friction, settings)
    work = _WORKSPACES[key]
    if guess is None:
        work.result.clearConstraintImpulseGuess()
    else:
        work.result.setConstraintImpulseGuess(np.asarray(guess, dtype=float).reshape(-1))
    operator = pin.DelassusOperatorDense(np.ascontiguousarray(delassus))
    converged = bool(work.solver.solve(operator, velocity, work.models, work.datas, work.settings, work.result))
    impulses = np.array(work.result.retrieveConstraintImpulses())
    if settings.polish and count:
        polished = polish(delassus, velocity, friction, impulses)
        if polished is not None:
            return polished, int(work.result.iterations), True
    return impulses, int(work.result.iterations), converged


def polish(delassus: np.ndarray, velocity: np.ndarray, friction: float, impulses: np.ndarray) -> np.ndarray | None:
    """The exact impulses of the contact modes ``impulses`` shows (module docstring), or
    ``None`` when they are not a solution of the cone complementarity problem."""
    p, u = impulses.reshape(-1, 3), (delassus @ impulses + velocity).reshape(-1, 3)
    scale_p = max(float(np.abs(p).max()), 1e-300)
    scale_u = max(float(np.abs(velocity).max()), 1e-300)
    slip = np.hypot(u[:, 0], u[:, 1])
    closed = p[:, 2] > 1e-6 * scale_p  # the others are open
    slipping = closed & ((friction == 0.0) | (slip > 1e-6 * scale_u))  # frictionless: the normal row only
    sticking, sliding = np.flatnonzero(closed & ~slipping), np.flatnonzero(slipping)
    stuck_rows = (3 * sticking[:, None] + np.arange(3)).ravel()
    rows = np.concatenate([stuck_rows, 3 * sliding + 2])
    if not len(rows):
        solution = np.zeros_like(velocity)
    else:
        basis = np.zeros((len(velocity), len(rows)))
        basis[stuck_rows, np.arange(len(stuck_rows))] = 1.0
        columns = len(stuck_rows) + np.arange(len(sliding))
        direction = u[sliding, :2] / np.maximum(slip[sliding], 1e-300)[:, None]
        basis[3 * sliding, columns] = -friction * direction[:, 0]
        basis[3 * sliding + 1, columns] = -friction * direction[:, 1]
        basis[3 * sliding + 2, columns] = 1.0
        solution = basis @ _least_norm((delassus @ basis)[rows], -velocity[rows], impulses)
    return solution if _solves(delassus, velocity, friction, solution, u) else None


def _least_norm(matrix: np.ndarray, target: np.ndarray, impulses: np.ndarray) -> np.ndarray:
    """``matrix⁻¹ target`` by one LU solve when ``matrix`` is regular (the answer no larger
    than 10³ times the impulses' scale: the target's free velocities, up to ``g / dt`` of far
    points, are no scale of impulses), else the least-norm solution (redundant rows)."""
    bound = 1e3 * max(float(np.abs(impulses).max()), 1e-300)
    try:
        with np.errstate(all="ignore"):
            solution = np.linalg.solve(matrix, target)
        if np.isfinite(solution).all() and float(np.abs(solution).max()) <= bound:
            return solution
    except np.linalg.LinAlgError:
        pass
    return np.linalg.lstsq(matrix, target, rcond=1e-10)[0]


def _solves(delassus: np.ndarray, velocity: np.ndarray, friction: float, solution: np.ndarray, before: np.ndarray) -> bool:
    """Whether ``solution`` solves the problem (to :data:`POLISH_TOLERANCE`), its slips
    continuing along ADMM's (``before``)."""
    p, u = solution.reshape(-1, 3), (delassus @ solution + velocity).reshape(-1, 3)
    size_p = POLISH_TOLERANCE * max(float(np.abs(p).max()), 1e-12)
    size_u = POLISH_TOLERANCE * max(float(np.abs(velocity).max()), 1e-12)
    normal, speed = p[:, 2], u[:, 2]
    bad = (normal < -size_p) | (np.hypot(p[:, 0], p[:, 1]) > friction * normal + size_p)  # outside a cone
    bad |= (speed < -size_u) | (
        np.abs(speed) * np.abs(normal) > size_u * size_p / POLISH_TOLERANCE
    )  # penetrating, or pushing apart
    turned = u[:, 0] * before[:, 0] + u[:, 1] * before[:, 1] <= 0
    bad |= (np.hypot(u[:, 0], u[:, 1]) > size_u) & (normal > size_p) & turned  # a slip that changed direction
    return not bool(bad.any())


__all__ = ["POLISH_TOLERANCE", "ContactSettings", "polish", "solve_impulses"]
