"""Physically consistent identification: a semidefinite program over the standard parameters.

A body's standard parameters ``(m, h = m c, Ī)`` (``Ī`` about the body origin) are those of a
real mass distribution exactly when its pseudo-inertia matrix

    J = [[Σ, h], [hᵀ, m]],   Σ = ½ tr(Ī) 1 − Ī   (the second moment ∫ r rᵀ dm),

is positive semidefinite (Wensing, Kim and Slotine, "Linear matrix inequalities for
physically consistent inertial parameter identification", 2017). Here each selected body
gets a PSD 4×4 variable ``J`` and its parameters are read off linearly
(``m = J₃₃``, ``h = J[:3, 3]``, ``Ī = tr(Σ) 1 − Σ``), so the constraints hold by construction.
Friction coefficients are constrained non-negative. Requires cvxpy (``pip install
'.[ident]'`` in robodyn's clone).
"""

from __future__ import annotations

import warnings

import numpy as np

from robodyn.exceptions import IdentificationError
from robodyn.ident.base import BaseParameters

#: Weight of the pull towards the URDF's standard parameters, relative to the mean
#: diagonal of the (weighted) normal matrix.
PHYSICAL_REGULARISATION = 1e-6
#: Solvers tried in order (both install with cvxpy from PyPI).
SOLVERS = ("CLARABEL", "SCS")


def _body_parameters(cp, J):
    """The 10 standard parameters of a pseudo-inertia ``J`` (cvxpy expression)."""
    sigma = J[:3, :3]
    trace = sigma[0, 0] + sigma[1, 1] + sigma[2, 2]
    inertia = [trace - sigma[0, 0], -sigma[0, 1], trace - sigma[1, 1], -sigma[0, 2], -sigma[1, 2], trace - sigma[2, 2]]
    return [J[3, 3], J[0, 3], J[1, 3], J[2, 3], *inertia]


def physical_parameters(
    base: BaseParameters, w: np.ndarray, target: np.ndarray, weights: np.ndarray, *, regularisation: float | None = None
) -> tuple[np.ndarray, str]:
    """Physically consistent standard parameters over ``base.columns``.

    The residual is that of the base parameters ``K π`` (the base regressor is well
    conditioned where the standard one is rank-deficient), so the problem is
    ``min |R_b K π − z|² + λ |π − π_URDF|²`` with ``W_b = Q_b R_b`` (weighted) and
    ``z = Q_bᵀ y``, over the parameters of physically consistent bodies.

    Args:
        base: The base parameter set (its columns: 10 a body, then friction if any).
        w: Base regressor of the data, shape (N, nv, count).
        target: Torques to explain, shape (N, nv).
        weights: Row weights (1/σ per joint), shape (N, nv).
        regularisation: ``λ`` relative to the mean diagonal of ``R_bᵀ R_b``
            (default ``PHYSICAL_REGULARISATION``).

    Returns:
        The standard parameters (p,) and the solver's name.

    Raises:
        IdentificationError: If cvxpy is missing or no solver reaches an optimal solution.
    """
    try:
        import cvxpy as cp
    except ImportError:
        raise IdentificationError(
            base.robot.name, "the physical method needs cvxpy (pip install cvxpy, or '.[ident]' in robodyn's clone)"
        ) from None
    count = w.shape[-1]
    matrix = (w * weights[..., None]).reshape(-1, count)
    rhs = (target * weights).reshape(-1)
    q_factor, r_factor = np.linalg.qr(matrix)
    projected = q_factor.T @ rhs
    scale = max(float(np.linalg.norm(projected)), 1e-300)
    nominal = base._standard[base.columns]
    p = nominal.size
    weight = (PHYSICAL_REGULARISATION if regularisation is None else regularisation) * float(np.sum(r_factor**2)) / count
    friction = 2 * base.robot.nv if base.friction else 0
    pseudo = [cp.Variable((4, 4), PSD=True) for _ in range((p - friction) // 10)]
    variables = cp.hstack([term for J in pseudo for term in _body_parameters(cp, J)])
    if friction:
        variables = cp.hstack([variables, cp.Variable(friction, nonneg=True)])
    residual = cp.sum_squares((r_factor @ base.mapping) @ variables - projected)
    problem = cp.Problem(cp.Minimize((residual + weight * cp.sum_squares(variables - nominal)) / scale**2))
    failures = []
    for solver in SOLVERS:
        if solver not in cp.installed_solvers():
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "inaccurate" is reported below instead
                problem.solve(solver=solver)
        except cp.error.SolverError as error:
            failures.append(f"{solver}: {error}")
            continue
        if problem.status == cp.OPTIMAL and variables.value is not None:
            return np.asarray(variables.value, dtype=float), solver
        failures.append(f"{solver}: {problem.status}")
    raise IdentificationError(
        base.robot.name, f"the physical identification did not solve ({'; '.join(failures) or 'no solver'})"
    )


__all__ = ["PHYSICAL_REGULARISATION", "SOLVERS", "physical_parameters"]
