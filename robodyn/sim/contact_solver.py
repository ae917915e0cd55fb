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
   slip direction ``s``); those equalities are solved exactly (one LU solve; least-norm,
   the constraints layer's rule, for redundant rows: more of them than the robot's ``nv``,
   or an LU answer over 10³ times the impulses' scale) and the result kept only when it is a
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
    delassus: np.ndarray, velocity: np.ndarray, friction: float, settings: ContactSettings, guess: np.ndarray | None = None,
    *, dofs: int | None = None,
) -> tuple[np.ndarray, int, bool]:  # fmt: skip
    """The impulses ``p`` (3k,) of the cone complementarity problem ``u = A p + c``
    (module docstring), with ADMM's iterations and whether it converged.

    Args:
        delassus: The Delassus matrix ``A``, shape (3k, 3k), in [m/(N s)] (or per joint unit).
        velocity: The free velocity ``c`` with the gaps' bias, shape (3k,), in [m/s].
        friction: The friction coefficient ``μ`` of every cone.
        settings: ADMM's tolerance and iterations, and whether its answer is polished.
        guess: Warm start: the previous step's impulses (3k,) or (k, 3), in [N s], or ``None``.
        dofs: The most independent rows ``A`` can have (a robot's ``nv``: more rows are
            redundant, solved least-norm at once), or ``None`` if unknown.

    Returns:
        The impulses (3k,) in [N s], ADMM's iterations (0: the previous modes held), and
        whether they solve the problem to tolerance.
    """
    count = len(velocity) // 3
    if not count:  # no contact: nothing to solve (Pinocchio's ADMM would crash on no rows)
        return np.zeros(0), 0, True
    if settings.polish and guess is not None:  # the previous step's modes may still hold: no ADMM
        previous = np.asarray(guess, dtype=float).reshape(-1)
        for cone in (True, False):  # every closed contact sticking, then the modes its velocities show
            kept = polish(delassus, velocity, friction, previous, dofs=dofs, cone=cone)
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
        polished = polish(delassus, velocity, friction, impulses, dofs=dofs)
        if polished is not None:
            return polished, int(work.result.iterations), True
    return impulses, int(work.result.iterations), converged


def polish(
    delassus: np.ndarray, velocity: np.ndarray, friction: float, impulses: np.ndarray, *, dofs: int | None = None,
    cone: bool = False,
) -> np.ndarray | None:  # fmt: skip
    """The exact impulses of the contact modes ``impulses`` shows (module docstring), or
    ``None`` when they are not a solution of the cone complementarity problem. More
    equalities than ``dofs`` (the robot's ``nv``, if given) are redundant: least-norm at once.

    A closed contact slips when the velocity ``u = A p + c`` of the impulses moves it (by
    1e-6 of ``c``'s scale, or 1e-12 when its impulse is on its cone's boundary: far open
    points' ``g / dt`` inflate that scale, and a foot at the edge of sticking slips by
    micrometres a second, which read as sticking puts its impulse outside the cone); with
    ``cone`` (the previous step's impulses), every closed contact sticks if each impulse is
    inside its cone (to 1e-6), else ``None``: a robot standing while its joints move keeps
    its modes, which the velocities of last step's impulses would call slipping.

    Sticking contacts alone (a robot standing) are one solve of their rows of ``A``; a
    slipping one adds a column ``(−μ s, 1)`` of its normal impulse. The modes are read
    contact by contact on Python floats (a few contacts: cheaper than numpy's calls).

    Args:
        delassus: The Delassus matrix ``A``, shape (3k, 3k).
        velocity: The free velocity ``c`` with the gaps' bias, shape (3k,), in [m/s].
        friction: The friction coefficient ``μ`` of every cone.
        impulses: The impulses whose modes are solved (ADMM's, or the previous step's), shape (3k,), in [N s].
        dofs: As for :func:`solve_impulses`.
        cone: Whether every closed contact is taken as sticking (``impulses``: the previous step's).
    """
    before = delassus @ impulses + velocity
    p, u = impulses.tolist(), before.tolist()
    scale_p = max(max(map(abs, p)), 1e-300)
    scale_u = max(max(map(abs, velocity.tolist())), 1e-300)
    stuck: list[int] = []
    sliding: list[tuple[int, float, float]] = []
    for index in range(0, len(p), 3):
        if p[index + 2] > 1e-6 * scale_p:  # closed (the others are open)
            if cone and not math.hypot(p[index], p[index + 1]) < (1 - 1e-6) * friction * p[index + 2]:
                return None  # on its cone's boundary (or frictionless): it slipped
            slip = 0.0 if cone else math.hypot(u[index], u[index + 1])
            edge = math.hypot(p[index], p[index + 1]) >= (1 - 1e-6) * friction * p[index + 2]  # on its cone
            if friction == 0.0 or slip > (1e-12 if edge else 1e-6) * scale_u:  # frictionless: the normal row only
                size = max(slip, 1e-300)
                sliding.append((index, u[index] / size, u[index + 1] / size))
            else:
                stuck += (index, index + 1, index + 2)
    redundant = dofs is not None and len(stuck) + len(sliding) > dofs
    if sliding:
        solution = _with_slips(delassus, velocity, friction, impulses, stuck, sliding, redundant)
    elif len(stuck) == len(p):  # every contact sticks
        solution = _least_norm(delassus, -velocity, 0.0 if redundant else _bound(impulses))
    else:
        solution = np.zeros_like(velocity)
        if stuck:
            target = -velocity[stuck]
            bound = 0.0 if redundant else _bound(impulses)
            solution[stuck] = _least_norm(delassus[np.ix_(stuck, stuck)], target, bound)
    return solution if _solves(delassus, velocity, friction, solution, u) else None


def _with_slips(
    delassus: np.ndarray, velocity: np.ndarray, friction: float, impulses: np.ndarray,
    stuck: list[int], sliding: list[tuple[int, float, float]], redundant: bool,
) -> np.ndarray:  # fmt: skip
    """The impulses of sticking rows ``stuck`` and slipping contacts ``sliding`` (first row, slip direction)."""
    basis = np.zeros((len(velocity), len(stuck) + len(sliding)))
    basis[stuck, np.arange(len(stuck))] = 1.0
    for column, (index, s1, s2) in enumerate(sliding, start=len(stuck)):
        basis[index : index + 3, column] = (-friction * s1, -friction * s2, 1.0)
    rows = stuck + [index + 2 for index, _, _ in sliding]
    target = -velocity[rows]
    return basis @ _least_norm((delassus @ basis)[rows], target, 0.0 if redundant else _bound(impulses))


def _bound(impulses: np.ndarray) -> float:
    """The largest answer an LU solve may give: 10³ times the impulses' scale (not the
    target's: its free velocities, up to ``g / dt`` of far points, are no scale of impulses —
    a singular set, the ant's feet and ankle stops, once passed 384 N s for 0.0022)."""
    return 1e3 * max(float(np.abs(impulses).max()), 1e-300)


def _least_norm(matrix: np.ndarray, target: np.ndarray, bound: float) -> np.ndarray:
    """``matrix⁻¹ target`` by one LU solve when ``matrix`` is regular (the answer no larger
    than ``bound``), else the least-norm solution (redundant rows; ``bound = 0``: at once)."""
    if bound <= 0.0:
        return np.linalg.lstsq(matrix, target, rcond=1e-10)[0]
    try:
        solution = np.linalg.solve(matrix, target)  # (numpy.linalg keeps its own errstate)
        if float(np.abs(solution).max()) <= bound:  # NaN and inf fail
            return solution
    except np.linalg.LinAlgError:
        pass
    return np.linalg.lstsq(matrix, target, rcond=1e-10)[0]


def _solves(delassus: np.ndarray, velocity: np.ndarray, friction: float, solution: np.ndarray, before: list[float]) -> bool:
    """Whether ``solution`` solves the problem (to :data:`POLISH_TOLERANCE`), its slips
    continuing along ADMM's (``before``: the velocities ``u`` of the modes' impulses)."""
    p, u = solution.tolist(), (delassus @ solution + velocity).tolist()
    size_p = POLISH_TOLERANCE * max(max(map(abs, p)), 1e-12)
    size_u = POLISH_TOLERANCE * max(max(map(abs, velocity.tolist())), 1e-12)
    pushing = size_u * size_p / POLISH_TOLERANCE
    for index in range(0, len(p), 3):
        normal, speed = p[index + 2], u[index + 2]
        if normal < -size_p or math.hypot(p[index], p[index + 1]) > friction * normal + size_p:
            return False  # outside its cone
        if speed < -size_u or abs(speed) * abs(normal) > pushing:
            return False  # penetrating, or pushing apart
        turned = u[index] * before[index] + u[index + 1] * before[index + 1] <= 0
        if turned and normal > size_p and math.hypot(u[index], u[index + 1]) > size_u:
            return False  # a slip that changed direction
    return True


__all__ = ["POLISH_TOLERANCE", "ContactSettings", "polish", "solve_impulses"]
