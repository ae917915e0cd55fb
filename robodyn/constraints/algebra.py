"""What a constraint's rows are, given the kinematics of its two ends (numpy only).

A constraint bound to a robot (:func:`bind`) has two **ends**: frames rigidly attached to
links (or to the world), each a position and a rotation in its link's frame. An engine
(Pinocchio in :mod:`robodyn.dynamics.constrained`, the reference's own kinematics in
:mod:`robodyn.reference.constraints`) supplies, for an end at a state, its world position
``p`` and rotation ``R``, its linear and angular Jacobians ``J_v``, ``J_ω`` (world axes at
the end's origin: ``ṗ = J_v v``, ``ω = J_ω v``) and its accelerations at ``v̇ = 0``
(``J̇_v v``, the classical acceleration, and ``J̇_ω v``). :func:`rows` turns the two ends
into the constraint's ``Φ``, ``J`` and ``J̇ v``:

============== ===== ========================================= ================================
constraint     rows  Φ(q)                                      J
============== ===== ========================================= ================================
PointAnchor    3     p₁ − p₂                                   J_v1 − J_v2
FrameAnchor    6     (p₁ − p₂, log(R₁ R₂ᵀ))                    (J_v1 − J_v2, J_ω1 − J_ω2)
PointContact   3     (n·(p − c)) n (the gap along the normal)  J_v
(μ > 0)
PointContact   1     n·(p − c)                                 nᵀ J_v
(μ = 0)
============== ===== ========================================= ================================

so that ``Φ̈ = J v̇ + J̇ v`` (for a weld's orientation rows and a sticking contact's
tangential rows, ``J v`` is the velocity the rows hold: they are not the derivative of
``Φ`` away from ``Φ = 0``). The equations of motion with multipliers ``λ`` are
``M v̇ + C v + G = τ + Jᵀ λ``: ``λ`` is the force (and torque) applied to the first end,
world axes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from robodyn.common.rotations import rpy_matrix
from robodyn.constraints.values import Constraint, FrameAnchor, PointAnchor, PointContact


@dataclass(frozen=True, eq=False)
class End:
    """A frame rigidly attached to a link (or the world), one end of a bound constraint.

    Attributes:
        link: The link's name, or ``None`` for the world.
        position: The frame's origin in the link's frame (world: in world coordinates), [m].
        rotation: The frame's rotation in the link's frame, shape (3, 3).
    """

    link: str | None
    position: np.ndarray
    rotation: np.ndarray


@dataclass(frozen=True, eq=False)
class Bound:
    """A constraint with both ends resolved (the neutral configuration's points filled in).

    Attributes:
        constraint: The constraint as given.
        first, second: Its two ends (a contact's second end is the world's plane point).
        rows: Its number of rows.
    """

    constraint: Constraint
    first: End
    second: End
    rows: int


class EndKinematics(NamedTuple):
    """An end's kinematics at one state (see the module docstring). ``nv`` columns."""

    position: np.ndarray
    rotation: np.ndarray
    linear: np.ndarray
    angular: np.ndarray
    linear_drift: np.ndarray
    angular_drift: np.ndarray


#: The world pose of a link at the neutral configuration: ``pose(link) -> (R, p)``.
NeutralPose = Callable[[str], tuple[np.ndarray, np.ndarray]]


def _placement(origin: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and position of ``(x, y, z, roll, pitch, yaw)``."""
    return rpy_matrix(np.asarray(origin[3:6], float)), np.asarray(origin[:3], float)


def _held_where(link: str | None, rotation: np.ndarray, position: np.ndarray, pose: NeutralPose) -> End:
    """The end on ``link`` that coincides with the world frame ``(rotation, position)``."""
    if link is None:
        return End(None, position, rotation)
    link_rotation, link_position = pose(link)
    return End(link, link_rotation.T @ (position - link_position), link_rotation.T @ rotation)


def bind(constraints: Sequence[Constraint], pose: NeutralPose) -> tuple[Bound, ...]:
    """Resolve each constraint's two ends (what is ``None`` is taken at the neutral configuration).

    Args:
        constraints: Constraints whose links were checked (:func:`~robodyn.constraints.values.check_frames`).
        pose: The world pose of a link at the robot's neutral configuration.
    """
    bound = []
    for constraint in constraints:
        if isinstance(constraint, PointAnchor):
            first = End(constraint.frame1, np.asarray(constraint.point1, float), np.eye(3))
            if constraint.point2 is None:
                rotation, position = pose(constraint.frame1)
                second = _held_where(constraint.frame2, np.eye(3), rotation @ first.position + position, pose)
            else:
                second = End(constraint.frame2, np.asarray(constraint.point2, float), np.eye(3))
        elif isinstance(constraint, FrameAnchor):
            first = End(constraint.frame1, *reversed(_placement(constraint.origin1)))
            if constraint.origin2 is None:
                rotation, position = pose(constraint.frame1)
                world = (rotation @ first.rotation, rotation @ first.position + position)
                second = _held_where(constraint.frame2, *world, pose)
            else:
                second = End(constraint.frame2, *reversed(_placement(constraint.origin2)))
        else:
            first = End(constraint.frame, np.asarray(constraint.point, float), np.eye(3))
            second = End(None, np.asarray(constraint.plane_point, float), np.eye(3))
        bound.append(Bound(constraint, first, second, constraint.rows))
    return tuple(bound)


def world_end(end: End, nv: int) -> EndKinematics:
    """The kinematics of an end fixed in the world: it never moves.

    Args:
        end: The end (its pose in the world frame).
        nv: Number of velocity coordinates.
    """
    zeros = np.zeros((3, nv))
    return EndKinematics(end.position, end.rotation, zeros, zeros, np.zeros(3), np.zeros(3))


def rotation_log(rotation: np.ndarray) -> np.ndarray:
    """The rotation vector (axis × angle in [rad], angle in [0, π]) of a rotation matrix.

    Args:
        rotation: A rotation matrix, shape (3, 3).
    """
    vector = 0.5 * np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]])
    sine = float(np.linalg.norm(vector))  # sin(angle) a; atan2 keeps the angle exact near π (acos does not)
    angle = math.atan2(sine, (float(np.trace(rotation)) - 1.0) / 2.0)
    if angle < 1e-6:
        return vector * (1.0 + angle * angle / 6.0)
    if math.pi - angle > 1e-6:
        return vector * (angle / sine)
    symmetric = ((rotation + rotation.T) / 2.0 + np.eye(3)) / 2.0  # ≈ a aᵀ near π (no sin [a]× part)
    column = int(np.argmax(np.diag(symmetric)))
    axis = symmetric[:, column] / math.sqrt(max(symmetric[column, column], 1e-300))
    return (-axis if float(axis @ vector) < 0.0 else axis) * angle  # the side sin(angle) a points to


def rows(bound: Bound, first: EndKinematics, second: EndKinematics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Φ``, ``J`` and ``J̇ v`` of one bound constraint from its ends' kinematics.

    Args:
        bound: The constraint with both ends resolved.
        first: Kinematics of its first end.
        second: Kinematics of its second end.

    Returns:
        Shapes (rows,), (rows, nv), (rows,).
    """
    constraint = bound.constraint
    gap = first.position - second.position
    jacobian = first.linear - second.linear
    drift = first.linear_drift - second.linear_drift
    if isinstance(constraint, FrameAnchor):
        phi = np.concatenate([gap, rotation_log(first.rotation @ second.rotation.T)])
        return (
            phi,
            np.vstack([jacobian, first.angular - second.angular]),
            np.concatenate([drift, first.angular_drift - second.angular_drift]),
        )
    if isinstance(constraint, PointContact):
        normal = np.asarray(constraint.normal)
        distance = float(normal @ gap)
        if constraint.rows == 1:
            return np.array([distance]), (normal @ jacobian)[None, :], np.array([normal @ drift])
        return distance * normal, jacobian, drift
    return gap, jacobian, drift


def stack(
    bounds: Sequence[Bound], kinematics: Callable[[End], EndKinematics], nv: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Φ`` (m,), ``J`` (m, nv) and ``J̇ v`` (m,) of a set of bound constraints at one state.

    Args:
        bounds: The constraints.
        kinematics: An end's kinematics at the state (an engine's; a world end may go to
            :func:`world_end`).
        nv: Size of a velocity.
    """
    parts = [rows(bound, kinematics(bound.first), kinematics(bound.second)) for bound in bounds]
    if not parts:
        return np.zeros(0), np.zeros((0, nv)), np.zeros(0)
    return tuple(np.concatenate([part[k] for part in parts]) for k in range(3))  # type: ignore[return-value]


class Layout:
    """The rows of a set of bound constraints as matrices: :func:`stack` for whole arrays.

    The ends of ``B`` constraints are numbered ``2 b`` (first) and ``2 b + 1`` (second); those
    on links (:attr:`linked`, in order) move, those of the world are constants. With the
    linked ends' positions (k, 3), Jacobians ``(J_v; J_ω)`` (k, 6, nv) and drifts
    ``(J̇_v v; J̇_ω v)`` (k, 6) stacked, one matrix ``T`` (m, 6 k) gives ``J = T J_ends`` and
    ``J̇ v = T (J̇ v)_ends``: it takes first minus second end and picks the rows of the
    module docstring's table (a block's linear rows, a weld's six, a sliding contact's
    ``nᵀ``). ``Φ = T_Φ p_ends + c`` likewise (a sticking contact's rows ``n nᵀ`` of the gap;
    ``c`` the world ends' part), a weld's rotation rows ``log(R₁ R₂ᵀ)`` then written in.
    The same numbers as :func:`stack`, without a Python loop over constraints.

    Attributes:
        rows: ``m``, the number of rows.
        linked: The numbers of the ends on links; :attr:`links` their link names.
    """

    def __init__(self, bounds: Sequence[Bound]) -> None:
        ends = [end for bound in bounds for end in (bound.first, bound.second)]
        self.rows = sum(bound.rows for bound in bounds)
        self.linked = [number for number, end in enumerate(ends) if end.link is not None]
        self.links = [str(ends[number].link) for number in self.linked]
        self.rotations = [end.rotation for end in ends]
        offsets = np.cumsum([0, *(bound.rows for bound in bounds)])
        self.welds = [
            (index, int(offsets[index]) + 3) for index, bound in enumerate(bounds) if isinstance(bound.constraint, FrameAnchor)
        ]
        picks, residual = np.zeros((self.rows, 6 * len(bounds))), np.zeros((self.rows, 3 * len(bounds)))
        for index, bound in enumerate(bounds):
            rows, six, three = slice(offsets[index], offsets[index + 1]), 6 * index, 3 * index
            normal = np.asarray(getattr(bound.constraint, "normal", (0.0, 0.0, 1.0)))
            if isinstance(bound.constraint, PointContact) and bound.rows == 1:
                picks[rows, six : six + 3] = residual[rows, three : three + 3] = normal
            elif isinstance(bound.constraint, PointContact):
                picks[rows, six : six + 3], residual[rows, three : three + 3] = np.eye(3), np.outer(normal, normal)
            else:
                picks[rows, six : six + bound.rows] = np.eye(bound.rows)
                residual[rows.start : rows.start + 3, three : three + 3] = np.eye(3)
        signs = [1.0 - 2.0 * (number % 2) for number in range(len(ends))]  # first end +, second −
        moving, moved = np.zeros((6 * len(bounds), 6 * len(self.linked))), np.zeros((3 * len(bounds), 3 * len(self.linked)))
        for column, number in enumerate(self.linked):
            moving[6 * (number // 2) : 6 * (number // 2) + 6, 6 * column : 6 * column + 6] = signs[number] * np.eye(6)
            moved[3 * (number // 2) : 3 * (number // 2) + 3, 3 * column : 3 * column + 3] = signs[number] * np.eye(3)
        fixed = np.zeros(3 * len(bounds))
        for number, end in enumerate(ends):
            if end.link is None:
                fixed[3 * (number // 2) : 3 * (number // 2) + 3] += signs[number] * np.asarray(end.position, float)
        self.selection, self.residual_selection, self.residual_offset = picks @ moving, residual @ moved, residual @ fixed

    def assemble(
        self, positions: np.ndarray, rotations: Sequence[np.ndarray], jacobians: np.ndarray, drifts: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``Φ`` (m,), ``J`` (m, nv), ``J̇ v`` (m,) from the linked ends' kinematics.

        Args:
            positions: Each linked end's world position, shape (k, 3), in [m].
            rotations: Their world rotations, each (3, 3).
            jacobians: Their ``(J_v; J_ω)``, shape (k, 6, nv), world axes at each end's point.
            drifts: Their ``(J̇_v v; J̇_ω v)``, shape (k, 6).
        """
        residual = self.residual_selection @ positions.reshape(-1) + self.residual_offset
        if self.welds:
            frames = list(self.rotations)
            for number, rotation in zip(self.linked, rotations, strict=True):
                frames[number] = rotation
            for index, row in self.welds:
                residual[row : row + 3] = rotation_log(frames[2 * index] @ frames[2 * index + 1].T)
        return residual, self.selection @ jacobians.reshape(len(jacobians) * 6, -1), self.selection @ drifts.reshape(-1)


def row_labels(constraints: Sequence[Constraint]) -> list[tuple[str, str, str]]:
    """``(constraint, component, unit)`` of every row of ``λ`` (and ``Φ``), in order.

    A constraint is called by its name, else ``<kind><index>`` (``point_anchor0``); a name
    used twice gets ``#<index>`` appended. Components: ``x``, ``y``, ``z`` [N] of a point
    anchor or a sticking contact; ``x``, ``y``, ``z`` [N] then ``mx``, ``my``, ``mz``
    [N m] of a weld; ``n`` [N] of a sliding contact (its normal force). The names are as
    given: escape them (:mod:`robodyn.common.text`) before printing.

    Args:
        constraints: The constraints.
    """
    names = [c.name or f"{c.kind.replace(' ', '_')}{index}" for index, c in enumerate(constraints)]
    names = [name if names.count(name) == 1 else f"{name}#{index}" for index, name in enumerate(names)]
    labels = []
    for name, constraint in zip(names, constraints, strict=True):
        if isinstance(constraint, FrameAnchor):
            labels += [(name, axis, "N") for axis in "xyz"] + [(name, f"m{axis}", "N m") for axis in "xyz"]
        elif constraint.rows == 1:
            labels.append((name, "n", "N"))
        else:
            labels += [(name, axis, "N") for axis in "xyz"]
    return labels


__all__ = [
    "Bound",
    "End",
    "EndKinematics",
    "Layout",
    "NeutralPose",
    "bind",
    "rotation_log",
    "row_labels",
    "rows",
    "stack",
    "world_end",
]
