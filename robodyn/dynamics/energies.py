"""Kinetic and potential energy of a robot, functions of its :class:`~robodyn.dynamics.handle.ModelHandle`.

Pinocchio's ``computeKineticEnergy`` and ``computePotentialEnergy`` refuse mimic joints:
the kinetic energy comes from the mass matrix, the potential energy of a robot with mimic
joints from its expanded model (:mod:`robodyn.dynamics.mimic`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from robodyn.dynamics.handle import ModelHandle, per_state


def kinetic_energy(handle: ModelHandle, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
    """Kinetic energy ``½ vᵀ M(q) v`` in [J]: a float, or shape (N,) for a batch.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).
    """
    (q, v), batch = handle.validate(q=q, v=v)
    mass_matrix = handle.kernels.M.single
    energy = per_state(lambda qi, vi: np.array(0.5 * vi @ mass_matrix(qi) @ vi), q, v)
    energy = handle.finite(np.asarray(energy), "kinetic energy")
    return energy if batch else float(energy)


def potential_energy(handle: ModelHandle, q: np.ndarray) -> float | np.ndarray:
    """Gravitational potential energy ``−Σ m_i gᵀ p_i`` in [J]: a float, or shape (N,).

    Zero when every centre of mass is at height zero (for the default gravity).

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
    """
    (q,), batch = handle.validate(q=q)
    mimic = handle.mimic
    if mimic is None:
        model, data = handle.model, handle.data
        energy = per_state(lambda qi: np.array(pin.computePotentialEnergy(model, data, qi)), q)
    else:
        energy = per_state(lambda qi: np.array(pin.computePotentialEnergy(mimic.model, mimic.data, mimic.q(qi))), q)
    energy = handle.finite(np.asarray(energy), "potential energy")
    return energy if batch else float(energy)


__all__ = ["kinetic_energy", "potential_energy"]
