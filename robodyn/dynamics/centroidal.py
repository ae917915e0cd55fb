"""Centroidal quantities of a robot: centre of mass, centroidal momentum and its matrix.

Functions of a :class:`~robodyn.dynamics.handle.ModelHandle` (Pinocchio's
``centerOfMass`` and ``computeCentroidalMap``, the composite rigid-body route of Orin and
Goswami). The centroidal momentum ``h = A_G(q) v`` is the linear momentum ``m ċ`` [kg m/s]
then the angular momentum about the centre of mass [kg m²/s], both in world axes (the
centroidal frame: origin at the centre of mass, axes the world's). They are the moving
bodies' (Pinocchio's convention): the links of a fixed-base robot welded to the world
neither move nor count in the centre of mass; a floating robot's are all of it. A joint's armature is
not a body: it adds nothing here. A robot with mimic joints is computed on its expanded
model (:mod:`robodyn.dynamics.mimic`): ``c(q) = c_full(Q q + offset)`` and
``A_G = A_G,full S``. The independent check is the reference's sums body by body
(:mod:`robodyn.reference.centroidal`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from robodyn.dynamics.handle import ModelHandle, per_state


def _expanded(handle: ModelHandle) -> tuple[pin.Model, pin.Data, Callable[[np.ndarray], np.ndarray], np.ndarray | None]:
    """The model to compute on, its data, the map of ``q`` to it and ``S`` (``None``: identity)."""
    mimic = handle.mimic
    if mimic is None:
        return handle.model, handle.data, lambda q: q, None
    return mimic.model, mimic.data, mimic.q, mimic.selection


def center_of_mass(handle: ModelHandle, q: np.ndarray) -> np.ndarray:
    """The centre of mass of the moving bodies (a floating robot: all of it), world axes.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).

    Returns:
        Shape (3,) or (N, 3), in [m].
    """
    (q,), _ = handle.validate(q=q)
    model, data, to_model, _ = _expanded(handle)
    result = per_state(lambda qi: pin.centerOfMass(model, data, to_model(qi), False).copy(), q)
    return handle.finite(np.asarray(result), "centre of mass")


def centroidal_momentum_matrix(handle: ModelHandle, q: np.ndarray) -> np.ndarray:
    """``A_G(q)``: the centroidal momentum is ``A_G v`` (linear rows, then angular about
    the centre of mass, world axes).

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).

    Returns:
        Shape (6, nv) or (N, 6, nv): [kg] on the linear rows, [kg m] / [kg m²] on the
        angular rows (per [m/s] / [rad/s] of ``v``).
    """
    (q,), _ = handle.validate(q=q)
    model, data, to_model, selection = _expanded(handle)

    def matrix(qi: np.ndarray) -> np.ndarray:
        full = pin.computeCentroidalMap(model, data, to_model(qi)).reshape(6, model.nv)
        return full.copy() if selection is None else full @ selection

    return handle.finite(np.asarray(per_state(matrix, q)), "centroidal momentum matrix")


def centroidal_momentum(handle: ModelHandle, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``h = A_G(q) v``: linear momentum [kg m/s] then angular momentum about the centre of
    mass [kg m²/s], world axes.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).

    Returns:
        Shape (6,) or (N, 6).
    """
    (q, v), _ = handle.validate(q=q, v=v)
    matrix = centroidal_momentum_matrix(handle, q)
    return np.einsum("...ij,...j->...i", matrix, v)


__all__ = ["center_of_mass", "centroidal_momentum", "centroidal_momentum_matrix"]
