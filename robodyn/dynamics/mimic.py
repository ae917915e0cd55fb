"""Mimic joints as a linear map onto the same robot with every joint free.

Pinocchio honours ``<mimic>`` in RNEA and CRBA but not in ABA, the energies or the
Coriolis matrix. For those robodyn builds the *expanded* model, where each mimic joint is
an independent joint, and maps states to it: ``q_mimic = multiplier * q_source + offset``
is linear, so ``q_full = Q q + offset``, ``v_full = S v``, ``M = Sᵀ M_full S`` and
``C = Sᵀ C_full S``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from robodyn.dynamics.batch import PerThreadData
from robodyn.urdf.validation import URDFSpec


@dataclass
class MimicExpansion:
    """The map from a robot with mimic joints to the same robot with every joint free.

    Attributes:
        model: The Pinocchio model with mimic joints as independent joints.
        selection: ``S``, shape (nv_full, nv).
        offset: Shape (nq_full,).
        q_selection: ``Q``, shape (nq_full, nq) (differs from ``S`` with a floating base).
    """

    model: pin.Model
    selection: np.ndarray
    offset: np.ndarray
    q_selection: np.ndarray
    _data: PerThreadData = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._data = PerThreadData(self.model)

    @property
    def data(self) -> pin.Data:
        """This thread's data for the expanded model."""
        return self._data.get()

    def q(self, q: np.ndarray) -> np.ndarray:
        """Configuration of the expanded model, shape (nq_full,).

        Args:
            q: Configuration of the model with mimic joints folded, shape (nq,).
        """
        return self.q_selection @ q + self.offset


def has_mimic(model: pin.Model, spec: URDFSpec, floating: bool) -> bool:
    """Whether Pinocchio folded mimic joints into ``model`` (fewer coordinates than joints).

    Args:
        model: The Pinocchio model.
        spec: The URDF it was built from.
        floating: Whether the model has a free-flyer root.
    """
    free = (7 if floating else 0) + sum(joint.type != "fixed" for joint in spec.joints.values())
    return model.nq != free


def mimic_expansion(model: pin.Model, spec: URDFSpec, full: pin.Model) -> MimicExpansion:
    """The map from ``model`` (mimic joints folded) to ``full``, the model of the same
    spec with every joint free (built by :func:`robodyn.dynamics.loading.build_model`).

    Args:
        model: The model with mimic joints folded.
        spec: The URDF both were built from.
        full: The model with every joint free.
    """
    selection = np.zeros((full.nv, model.nv))
    q_selection = np.zeros((full.nq, model.nq))
    offset = np.zeros(full.nq)
    for joint_id in range(1, full.njoints):
        name = full.names[joint_id]
        full_joint = full.joints[joint_id]
        urdf_joint = spec.joints.get(name)
        source, multiplier = name, 1.0
        if urdf_joint is not None and urdf_joint.mimic is not None:
            source, multiplier = urdf_joint.mimic.joint, urdf_joint.mimic.multiplier
            offset[full_joint.idx_q] = urdf_joint.mimic.offset
        source_joint = model.joints[model.getJointId(source)]
        for k in range(full_joint.nv):
            selection[full_joint.idx_v + k, source_joint.idx_v + k] = multiplier
        for k in range(full_joint.nq):  # a free flyer: 7 position coordinates, copied
            q_selection[full_joint.idx_q + k, source_joint.idx_q + k] = multiplier
    return MimicExpansion(full, selection, offset, q_selection)
