"""The reference with multipliers: ``Φ(q)``, ``J``, ``J̇ v`` and the KKT system, without Pinocchio.

The rows are :mod:`robodyn.constraints.algebra`'s; the kinematics of their ends comes from
the reference's own forward kinematics (:meth:`ReferenceRobot._kinematics`, the bodies of
:mod:`robodyn.reference.tree`). A link welded to a body by fixed joints is found by walking
the URDF's fixed joints up to that body (or the root). For a point ``p`` on body ``b`` and
joint ``i`` (world axis ``z_i``, origin ``o_i``) ancestor of ``b``:

    J_v[:, i] = z_i × (p − o_i)  (revolute) or z_i (prismatic),   J_ω[:, i] = z_i (revolute)

and, at ``θ̈ = 0``, differentiating along the motion: ``ż_i = ω_i⁻ × z_i`` (``ω_i⁻`` the
angular velocity of the body the joint hangs from), so

    J̇_v θ̇ = Σ_i θ̇_i (ż_i × (p − o_i) + z_i × (ṗ − ȯ_i))  (revolute; ż_i prismatic),
    J̇_ω θ̇ = Σ_i θ̇_i ż_i                                    (revolute).

Joints' coordinates map to bodies by ``θ = S q + offset`` (mimic joints), ``θ̇ = S v``. A
floating base's virtual joints sit at zero under the base pose; their accelerations are
``a + bias(v)`` (:func:`robodyn.reference.numeric._base_bias`), so ``J̇ v`` gains
``J bias(v)``. The KKT system ``[[M, −Jᵀ], [J, 0]] (a, λ) = (τ − C v − G, −J̇ v)`` is
solved whole by least squares (SVD, singular values below :data:`RCOND` of the largest
dropped): the least-norm ``λ`` for a redundant set, as the dynamics layer gives by another
route.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robodyn.common.inputs import as_states
from robodyn.common.rotations import rpy_matrix
from robodyn.constraints import Constraint, as_constraints, check_frames
from robodyn.constraints.algebra import Bound, End, EndKinematics, bind, stack, world_end
from robodyn.reference.numeric import ReferenceRobot, _base_bias, _quaternion_matrix

#: Relative cut-off of the KKT matrix's singular values.
RCOND = 1e-11


def link_frames(model: ReferenceRobot) -> dict[str, tuple[int, np.ndarray]]:
    """Every link: the body carrying it (−1: the fixed root) and its 4×4 pose in that body's frame.

    Args:
        model: The reference model of the robot.
    """
    body_of = {body.link: index for index, body in enumerate(model.tree.bodies) if not body.rotor}
    if model.floating_base:
        body_of[model.spec.root] = 5
    parent_joint = {joint.child: joint for joint in model.spec.joints.values()}
    frames: dict[str, tuple[int, np.ndarray]] = {}

    def frame(link: str) -> tuple[int, np.ndarray]:
        if link not in frames:
            if link in body_of:
                frames[link] = (body_of[link], np.eye(4))
            elif link not in parent_joint:  # the fixed root
                frames[link] = (-1, np.eye(4))
            else:  # welded to its parent by a fixed joint (a locked joint included)
                joint = parent_joint[link]
                body, to_parent = frame(joint.parent)
                origin = np.eye(4)
                origin[:3, :3], origin[:3, 3] = rpy_matrix(np.asarray(joint.origin_rpy, float)), joint.origin_xyz
                frames[link] = (body, to_parent @ origin)
        return frames[link]

    for link in model.spec.links:
        frame(link)
    return frames


class _State:
    """The reference's kinematics of every body at one state (θ-coordinates)."""

    def __init__(self, model: ReferenceRobot, q: np.ndarray, v: np.ndarray) -> None:
        base = None
        if model.floating_base:
            base = (_quaternion_matrix(q[None, 3:7]), q[None, :3])
            q = np.concatenate([np.zeros(6), q[7:]])
        selection = model.tree.selection
        theta = selection @ q + model.tree.offset
        rotations, positions, axes, origins = model._kinematics(theta[None], base)
        self.rotations, self.positions, self.axes, self.origins = rotations[0], positions[0], axes[0], origins[0]
        self.rate = selection @ v
        self.selection = selection
        self.revolute = np.array([body.revolute for body in model.tree.bodies])
        self.ancestors = model.tree.ancestors
        strict = self.ancestors & ~np.eye(len(theta), dtype=bool)  # strict[i, j]: j a strict ancestor of i
        spin = np.where(self.revolute[:, None], self.axes * self.rate[:, None], 0.0)
        self.omega_before = strict.astype(float) @ spin  # angular velocity of the body joint i hangs from
        self.axis_rates = np.cross(self.omega_before, self.axes)  # ż_i
        self.origin_rates = np.array(
            [self._point_jacobian(self.origins[i], strict[i])[0] @ self.rate for i in range(len(theta))]
        ).reshape(-1, 3)

    def _point_jacobian(self, point: np.ndarray, moves: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Linear and angular Jacobians (3, B) in θ̇ of a world point moved by the bodies ``moves``."""
        lever = point[None, :] - self.origins
        linear = np.where(self.revolute[:, None], np.cross(self.axes, lever), self.axes) * moves[:, None]
        angular = np.where(self.revolute[:, None], self.axes, 0.0) * moves[:, None]
        return linear.T, angular.T

    def end(self, body: int, pose: np.ndarray) -> EndKinematics:
        """An end on ``body`` (−1: the root) at ``pose`` (4×4) in the body's frame."""
        if body < 0:
            rotation, position = pose[:3, :3], pose[:3, 3]
            nv = self.selection.shape[1]
            return world_end(End(None, position, rotation), nv)
        rotation = self.rotations[body] @ pose[:3, :3]
        point = self.positions[body] + self.rotations[body] @ pose[:3, 3]
        moves = self.ancestors[body]
        linear, angular = self._point_jacobian(point, moves)
        rate = self.rate * moves
        velocity = linear @ self.rate
        lever = point[None, :] - self.origins
        revolute = self.revolute[:, None]
        per_joint = np.where(
            revolute,
            np.cross(self.axis_rates, lever) + np.cross(self.axes, velocity[None, :] - self.origin_rates),
            self.axis_rates,
        )
        linear_drift = rate @ per_joint
        angular_drift = (rate * self.revolute) @ self.axis_rates
        return EndKinematics(point, rotation, linear @ self.selection, angular @ self.selection, linear_drift, angular_drift)


def bound(model: ReferenceRobot, constraints: Sequence[Constraint] | object) -> tuple[tuple[Bound, ...], dict]:
    """The constraints with both ends resolved on the reference, and its link frames.

    Args:
        model: The reference model of the robot.
        constraints: One constraint (a ``PointAnchor``, ``FrameAnchor`` or ``PointContact``) or a sequence of them.
    """
    given = as_constraints(constraints)
    check_frames(given, list(model.spec.links), model.name)
    frames = link_frames(model)
    neutral = np.zeros(model.nq)
    if model.floating_base:
        neutral[6] = 1.0
    state = _State(model, neutral, np.zeros(model.nv))

    def pose(link: str) -> tuple[np.ndarray, np.ndarray]:
        body, to_link = frames[link]
        if body < 0:
            return to_link[:3, :3], to_link[:3, 3]
        return state.rotations[body] @ to_link[:3, :3], state.positions[body] + state.rotations[body] @ to_link[:3, 3]

    return bind(given, pose), frames


def state_rows(
    model: ReferenceRobot, bounds: Sequence[Bound], frames: dict, q: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Φ`` (m,), ``J`` (m, nv), ``J̇ v`` (m,) at one state (the reference's coordinate order).

    Args:
        model: The reference model of the robot.
        bounds: The constraints bound to the model (:func:`bound`).
        frames: The link frames (:func:`link_frames`).
        q: Configuration, shape (nq,).
        v: Velocity, shape (nv,).
    """
    state = _State(model, q, v)

    def kinematics(end: End) -> EndKinematics:
        if end.link is None:
            return world_end(end, model.nv)
        body, to_link = frames[end.link]
        local = np.eye(4)
        local[:3, :3], local[:3, 3] = end.rotation, end.position
        return state.end(body, to_link @ local)

    phi, jacobian, drift = stack(bounds, kinematics, model.nv)
    if model.floating_base:
        drift = drift + jacobian @ _base_bias(v[None])[0]
    return phi, jacobian, drift


def constraint_terms(model: ReferenceRobot, q, v, constraints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Φ, J, J̇ v)``: shapes (m,), (m, nv), (m,) or stacked for a batch.

    Args:
        model: The reference model of the robot.
        q: Configuration, shape (nq,) or (N, nq), in the reference's joint order, in [rad] / [m].
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        constraints: One constraint (a ``PointAnchor``, ``FrameAnchor`` or ``PointContact``) or a sequence of them.
    """
    bounds, frames = bound(model, constraints)
    (q, v), batch = as_states({"q": (q, model.nq), "v": (v, model.nv)})
    if not batch:
        return state_rows(model, bounds, frames, q, v)
    rows = [state_rows(model, bounds, frames, qi, vi) for qi, vi in zip(q, v, strict=True)]
    m = sum(bound.rows for bound in bounds)
    if not rows:
        return np.zeros((0, m)), np.zeros((0, m, model.nv)), np.zeros((0, m))
    return tuple(np.array([row[k] for row in rows]) for k in range(3))  # type: ignore[return-value]


def solve_kkt(mass: np.ndarray, force: np.ndarray, jacobian: np.ndarray, drift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(a, λ)`` of ``[[M, −Jᵀ], [J, 0]] (a, λ) = (force, −J̇ v)`` by least squares.

    Args:
        mass: ``M``, shape (nv, nv).
        force: ``τ − C v − G``, shape (nv,), in [N m] / [N].
        jacobian: ``J``, shape (m, nv).
        drift: ``J̇ v``, shape (m,).
    """
    n, m = len(force), len(drift)
    kkt = np.block([[mass, -jacobian.T], [jacobian, np.zeros((m, m))]])
    solution = np.linalg.lstsq(kkt, np.concatenate([force, -drift]), rcond=RCOND)[0]
    return solution[:n], solution[n:]


def constrained_forward_dynamics(model: ReferenceRobot, q, v, tau, constraints) -> tuple[np.ndarray, np.ndarray]:
    """``(a, λ)`` of ``M a + C v + G = τ + Jᵀ λ``, ``J a + J̇ v = 0`` (the reference's order).

    Shapes (nv,), (m,), or stacked for a batch (one state a row).

    Args:
        model: The reference model of the robot.
        q: Configuration, shape (nq,) or (N, nq), in the reference's joint order, in [rad] / [m].
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        tau: Torques, shape (nv,) or (N, nv), in [N m] / [N].
        constraints: One constraint (a ``PointAnchor``, ``FrameAnchor`` or ``PointContact``) or a sequence of them.
    """
    bounds, frames = bound(model, constraints)
    (q, v, tau), batch = as_states({"q": (q, model.nq), "v": (v, model.nv), "tau": (tau, model.nv)})
    states = [(q, v, tau)] if not batch else list(zip(q, v, tau, strict=True))
    results = []
    for qi, vi, ti in states:
        _, jacobian, drift = state_rows(model, bounds, frames, qi, vi)
        results.append(solve_kkt(model.mass_matrix(qi), ti - model.nonlinear_effects(qi, vi), jacobian, drift))
    if not batch:
        return results[0]
    if not results:
        return np.zeros((0, model.nv)), np.zeros((0, sum(bound.rows for bound in bounds)))
    return np.array([r[0] for r in results]), np.array([r[1] for r in results])


__all__ = ["RCOND", "bound", "constrained_forward_dynamics", "constraint_terms", "link_frames", "solve_kkt", "state_rows"]
