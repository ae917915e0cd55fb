"""The equations of motion as Pinocchio calls: one function a quantity, for one state and for a batch.

:func:`dynamics_kernels` sets up, once per model, what :meth:`ModelHandle.evaluate
<robodyn.dynamics.handle.ModelHandle.evaluate>` computes for each quantity: a function of
one state (1-D arrays, unchecked: Pinocchio on the arguments as they are) and, where
Pinocchio has one, a parallel function of a batch (2-D arrays, one state a row).

Robots with mimic joints go through their expanded model (:mod:`robodyn.dynamics.mimic`)
where Pinocchio does not honour mimic joints (ABA, the Coriolis matrix).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.dynamics.mimic import MimicExpansion
from robodyn.exceptions import SingularMassMatrixError


class Kernel(NamedTuple):
    """How to compute one quantity (see :meth:`robodyn.dynamics.handle.ModelHandle.evaluate`).

    Attributes:
        what: The quantity, for messages (``"tau"``, ``"frame position"``).
        names: Names of the state arguments, in order (``("q", "v", "a")``), for messages.
        single: Its function of one state (1-D arrays).
        batch: Its function of a batch (2-D arrays), or ``None`` to apply ``single`` row by row.
    """

    what: str
    names: tuple[str, ...]
    single: Callable[..., np.ndarray]
    batch: Callable[..., np.ndarray] | None = None


class DynamicsKernels(NamedTuple):
    """The kernels of the equations of motion (built once per model by :func:`dynamics_kernels`).

    Attributes:
        tau: Inverse dynamics (RNEA) of ``q, v, a``.
        a: Forward dynamics (ABA, or a linear solve for mimic joints) of ``q, v, tau``.
        M: Mass matrix (CRBA) of ``q``.
        C: Coriolis matrix of ``q, v``.
        G: Generalised gravity of ``q``.
        nle: ``C(q, v) v + G(q)`` of ``q, v``.
    """

    tau: Kernel
    a: Kernel
    M: Kernel
    C: Kernel
    G: Kernel
    nle: Kernel


def massless_joints(model: pin.Model) -> list[str]:
    """Joints of ``model`` whose whole subtree has no mass, and :func:`redundant_free_flyers`:
    they make ``M(q)`` singular.

    Args:
        model: The Pinocchio model.
    """
    subtree_mass = [model.inertias[i].mass for i in range(model.njoints)]
    for joint_id in range(model.njoints - 1, 0, -1):
        subtree_mass[model.parents[joint_id]] += subtree_mass[joint_id]
    massless = [model.names[i] for i in range(1, model.njoints) if subtree_mass[i] <= 0 and model.joints[i].nv > 0]
    return massless + [name for name in redundant_free_flyers(model) if name not in massless]


def redundant_free_flyers(model: pin.Model) -> list[str]:
    """Free-flyer joints whose body has no mass and carries one moving joint: the body's six
    motions move that joint's whole subtree rigidly, as the joint does, so ``M(q)`` is
    singular (a massless floating root with one child link). Not claimed with mimic joints
    (``nv = 0`` here): a mimic in the subtree breaks the rigid motion.

    Args:
        model: The Pinocchio model.
    """
    if any(model.joints[j].nv == 0 for j in range(1, model.njoints)):
        return []
    out = []
    for i in range(1, model.njoints):
        children = [j for j in range(i + 1, model.njoints) if model.parents[j] == i and model.joints[j].nv > 0]
        if model.joints[i].nv == 6 and model.inertias[i].mass <= 0 and len(children) == 1:
            out.append(model.names[i])
    return out


def dynamics_kernels(
    model: pin.Model,
    data: Callable[[], pin.Data],
    run: Callable[..., np.ndarray],
    mimic: MimicExpansion | None,
    *,
    name: str,
) -> DynamicsKernels:
    """The kernels of the equations of motion of ``model``.

    Args:
        model: The Pinocchio model.
        data: Returns this thread's Pinocchio data for ``model``.
        run: Runs a Pinocchio parallel algorithm on stacks of states
            (:meth:`robodyn.dynamics.batch.ParallelRunner.run`).
        mimic: The expansion of a model with mimic joints, or ``None``.
        name: The robot's name, for messages.
    """
    mass = mass_matrix_function(model, data, mimic)
    nv = model.nv

    def solve(q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``M⁻¹ (tau − C v − G)`` by a linear solve (for models ABA cannot take)."""
        rhs = tau - pin.nonLinearEffects(model, data(), q, v)
        try:
            return np.linalg.solve(mass(q), rhs)
        except np.linalg.LinAlgError:
            raise SingularMassMatrixError(name, massless_joints(model)) from None

    def gravity_batch(q: np.ndarray) -> np.ndarray:
        zeros = np.zeros((q.shape[0], nv))
        return run(pin.rneaInParallel, q, zeros, zeros)

    forward = (
        Kernel("a", ("q", "v", "tau"), lambda q, v, tau: pin.aba(model, data(), q, v, tau), lambda *s: run(pin.abaInParallel, *s))
        if mimic is None
        else Kernel("a", ("q", "v", "tau"), solve)  # Pinocchio's ABA refuses mimic joints (abaInParallel crashes on them)
    )
    return DynamicsKernels(
        tau=Kernel(
            "tau", ("q", "v", "a"), lambda q, v, a: pin.rnea(model, data(), q, v, a), lambda *s: run(pin.rneaInParallel, *s)
        ),
        a=forward,
        M=Kernel("M", ("q",), mass),
        C=Kernel("C", ("q", "v"), coriolis_function(model, data, mimic)),
        G=Kernel("G", ("q",), lambda q: pin.computeGeneralizedGravity(model, data(), q), gravity_batch),
        nle=Kernel(
            "C v + G",
            ("q", "v"),
            lambda q, v: pin.nonLinearEffects(model, data(), q, v),
            lambda q, v: run(pin.rneaInParallel, q, v, np.zeros_like(v)),
        ),
    )


def mass_matrix_function(
    model: pin.Model, data: Callable[[], pin.Data], mimic: MimicExpansion | None
) -> Callable[[np.ndarray], np.ndarray]:
    """``M(q)`` of one state (CRBA), both triangles filled.

    Args:
        model: The Pinocchio model.
        data: Returns the Pinocchio data to compute in (this thread's).
        mimic: The expansion of a model with mimic joints, or ``None``.
    """
    lower_triangle = np.tri(model.nv, model.nv, -1, dtype=bool)
    # With a mimic joint between two free joints, Pinocchio 4.1's crba in its default LOCAL
    # convention accumulates into data from call to call; the WORLD convention does not
    # (tests/dynamics/test_robot.py, mimic_tree).
    convention = pin.Convention.LOCAL if mimic is None else pin.Convention.WORLD

    def mass_matrix(q: np.ndarray) -> np.ndarray:
        mass = pin.crba(model, data(), q, convention)  # upper triangle only
        np.copyto(mass, mass.T, where=lower_triangle)
        return mass

    return mass_matrix


def coriolis_function(
    model: pin.Model, data: Callable[[], pin.Data], mimic: MimicExpansion | None
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``C(q, v)`` of one state (computeCoriolisMatrix mishandles mimic joints: those go
    through the expanded model, ``C = Sᵀ C_full S``).

    Args:
        model: The Pinocchio model.
        data: Returns the Pinocchio data to compute in (this thread's).
        mimic: The expansion of a model with mimic joints, or ``None``.
    """
    if mimic is None:
        return lambda q, v: pin.computeCoriolisMatrix(model, data(), q, v)

    def coriolis(q: np.ndarray, v: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore"):  # inf inputs: the checks after report them
            full = pin.computeCoriolisMatrix(mimic.model, mimic.data, mimic.q(q), mimic.selection @ v)
            return mimic.selection.T @ full @ mimic.selection

    return coriolis


__all__ = [
    "DynamicsKernels",
    "Kernel",
    "coriolis_function",
    "dynamics_kernels",
    "mass_matrix_function",
    "massless_joints",
]
