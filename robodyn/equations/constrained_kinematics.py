"""The constrained ends' kinematics in closed form, for the derivation with multipliers.

An end of a bound constraint (:class:`robodyn.constraints.algebra.End`: a frame fixed to a
link, or to the world) as functions of ``q`` and ``q̇``: its world position ``p(q)``, its
rotation ``R(q)`` and its angular velocity ``ω(q, q̇) = Σ a_k θ̇_k``, the sum over the
revolute joints from the root to its body (``a_k`` a joint's world axis, ``θ̇_k`` its
speed), from the reference's forward kinematics (:func:`robodyn.reference.symbolic.body_poses`).
Exact numbers (the file's as rationals); no Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn import reference
from robodyn.constraints.algebra import End
from robodyn.equations.derivation import DerivationSteps
from robodyn.reference.constraints import link_frames
from robodyn.reference.symbolic import body_coordinates, body_poses, exact_matrix

#: Entries of a file's rotations and points within this of 0, ±½, ±√2/2, ±√3/2 or ±1 become exact.
SNAP = 1e-12


@dataclass(frozen=True)
class EndFrame:
    """An end as functions of ``q`` and ``q̇``.

    Attributes:
        position: ``p(q)`` (3 × 1), in [m], world coordinates.
        rotation: ``R(q)`` (3 × 3), its axes in world coordinates.
        omega: ``ω(q, q̇)`` (3 × 1), in [rad/s], world axes (linear in ``q̇``).
    """

    position: sp.Matrix
    rotation: sp.Matrix
    omega: sp.Matrix


class Kinematics:
    """The bodies' poses and angular velocities of a reference robot in closed form, computed once."""

    def __init__(self, model: reference.ReferenceRobot, steps: DerivationSteps) -> None:
        self.model, self.frames = model, link_frames(model)
        theta, theta_dot = body_coordinates(model, list(steps.q), list(steps.qd))
        self.rotations, self.positions, axes = body_poses(model, theta)
        self.omegas: list[sp.Matrix] = []
        for index, body in enumerate(model.tree.bodies):
            parent = sp.zeros(3, 1) if body.parent < 0 else self.omegas[body.parent]
            self.omegas.append(parent + axes[index] * theta_dot[index] if body.revolute else parent)

    def end(self, end: End) -> EndFrame:
        """An end's frame (:class:`EndFrame`).

        Args:
            end: A constraint's end (a link, or the world when its link is ``None``).
        """
        if end.link is None:
            return EndFrame(
                exact_matrix(np.asarray(end.position, float)[:, None], SNAP), exact_matrix(end.rotation, SNAP), sp.zeros(3, 1)
            )
        body, to_link = self.frames[end.link]
        position = exact_matrix((to_link[:3, :3] @ np.asarray(end.position, float) + to_link[:3, 3])[:, None], SNAP)
        rotation = exact_matrix(to_link[:3, :3] @ end.rotation, SNAP)
        if body < 0:
            return EndFrame(position, rotation, sp.zeros(3, 1))
        return EndFrame(
            sp.expand(self.positions[body] + self.rotations[body] * position),
            self.rotations[body] * rotation,
            self.omegas[body],
        )


def sine_vector(rotation: sp.Matrix) -> sp.Matrix:
    """``½ vee(R − Rᵀ) = sin θ a`` of a rotation ``R = exp(θ [a]×)``: zero exactly where its
    logarithm ``θ a`` is, for ``θ < π`` (how the derivation prints a weld's rotation rows).

    Args:
        rotation: A symbolic rotation matrix, 3 × 3.
    """
    skew = (rotation - rotation.T) / 2
    return sp.Matrix([skew[2, 1], skew[0, 2], skew[1, 0]]).applyfunc(lambda entry: sp.trigsimp(sp.expand(entry)))


__all__ = ["SNAP", "EndFrame", "Kinematics", "sine_vector"]
