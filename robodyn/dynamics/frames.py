"""Task frames: which frame of a robot is its end effector, and which frames can move.

A task (a position target, a payload, an external force) on a frame that no joint moves
does nothing, so every number computed from it would be silently wrong. This module
decides the default end effector and refuses static frames:

- A frame *moves* when some joint lies between it and the world (Pinocchio's parent joint
  of the frame is not the universe). Mimic joints count: they follow their source joint.
- The *default end effector* is the tip of the chain the last moving joint drives: the
  link carried by the leaf joint of the tree of moving joints, so its pose depends on
  every joint of that chain. From there, fixed frames are followed while the way is
  unique (one fixed child: ``panda_hand`` → ``panda_hand_tcp``); at a fork of fixed
  frames (ur5's ``wrist_3_link`` carries both ``ee_link`` and ``tool0``) the link itself
  is kept. A link named ``end_effector`` that moves is taken as given.
- A *gripper* is not a second chain: when the tree of moving joints forks at one link
  into branches of at most one independent joint each (panda's two fingers, one of them
  a mimic), with at most two independent joints in all, the end effector is that link
  (the hand), followed through fixed frames as above.
- Any other fork (legs, hands with several fingers, arms and a head, wheels) has no
  default: :class:`~robodyn.exceptions.AmbiguousEndEffectorError` lists the candidate tips.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from robodyn.exceptions import AmbiguousEndEffectorError, StaticFrameError

#: Largest number of independent joints of all gripper fingers together.
GRIPPER_JOINTS = 2


def moves(model: pin.Model, frame_id: int) -> bool:
    """Whether some joint moves a frame (its parent joint is not the universe).

    Args:
        model: The Pinocchio model.
        frame_id: The frame's index in ``model.frames``.
    """
    return model.frames[frame_id].parentJoint != 0


def moving_frames(model: pin.Model) -> list[str]:
    """Names of the link frames some joint moves, in model order.

    Args:
        model: The Pinocchio model.
    """
    return [f.name for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY and moves(model, i)]


def require_moving(model: pin.Model, robot: str, frame: str, frame_id: int, purpose: str) -> None:
    """Refuse a frame no joint moves for a task (``purpose``: what it is used for).

    Args:
        model: The Pinocchio model.
        robot: The robot's name, for the error.
        frame: The frame's name.
        frame_id: The frame's index in ``model.frames``.
        purpose: What the frame is used for, for the error.

    Raises:
        StaticFrameError: With the default end effector or some moving links as hints.
    """
    if moves(model, frame_id):
        return
    raise StaticFrameError(robot, frame, purpose, moving_frames(model)[-3:])


def _children(model: pin.Model) -> dict[int, list[int]]:
    children: dict[int, list[int]] = {joint: [] for joint in range(model.njoints)}
    for joint in range(1, model.njoints):
        children[model.parents[joint]].append(joint)
    return children


def _body_of_joint(model: pin.Model, joint: int) -> int:
    """The link frame carried directly by a joint."""
    joint_frame = next(i for i, f in enumerate(model.frames) if f.type == pin.FrameType.JOINT and f.parentJoint == joint)
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY and f.parentFrame == joint_frame]
    return bodies[0] if bodies else joint_frame


def _attached_to(model: pin.Model, joint: int) -> int:
    """The link frame a joint hangs from."""
    return next(f.parentFrame for f in model.frames if f.type == pin.FrameType.JOINT and f.parentJoint == joint)


def _follow_fixed(model: pin.Model, body: int) -> int:
    """From a link, follow fixed joints while each link has exactly one fixed child."""
    while True:
        fixed = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.FIXED_JOINT and f.parentFrame == body]
        if len(fixed) != 1:
            return body
        following = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY and f.parentFrame == fixed[0]]
        if len(following) != 1:
            return body
        body = following[0]


def end_effector_candidates(model: pin.Model) -> list[str]:
    """The tips of every chain of moving joints (one name a leaf joint).

    Args:
        model: The Pinocchio model.
    """
    children = _children(model)
    leaves = [joint for joint in range(1, model.njoints) if not children[joint]]
    return [model.frames[_follow_fixed(model, _body_of_joint(model, leaf))].name for leaf in leaves]


def default_end_effector(model: pin.Model, robot: str) -> str:
    """The default task frame of a robot (see the module docstring for the rule).

    Args:
        model: The Pinocchio model (mimic joints included, with ``nv == 0``).
        robot: The robot's name, for messages.

    Returns:
        A link name whose pose depends on every joint of its chain.

    Raises:
        AmbiguousEndEffectorError: If the moving joints form several chains (legs, hands).
    """
    names = {f.name: i for i, f in enumerate(model.frames)}
    if "end_effector" in names and moves(model, names["end_effector"]):
        return "end_effector"
    children = _children(model)
    leaves = [joint for joint in range(1, model.njoints) if not children[joint]]
    if len(leaves) == 1:
        return model.frames[_follow_fixed(model, _body_of_joint(model, leaves[0]))].name
    paths = [list(model.supports[leaf]) for leaf in leaves]
    depth = 0
    while all(len(path) > depth + 1 for path in paths) and len({path[depth + 1] for path in paths}) == 1:
        depth += 1
    common = paths[0][depth]  # deepest joint every chain shares (0: they share none)
    branches = [path[depth + 1 :] for path in paths]
    independent = [sum(model.joints[joint].nv for joint in branch) for branch in branches]
    hangs_from = {_attached_to(model, branch[0]) for branch in branches}
    if common != 0 and max(independent) <= 1 and sum(independent) <= GRIPPER_JOINTS and len(hangs_from) == 1:
        return model.frames[_follow_fixed(model, hangs_from.pop())].name
    raise AmbiguousEndEffectorError(robot, end_effector_candidates(model))


def reach(model: pin.Model, frame_id: int, lower, upper) -> tuple[list[float], float] | None:
    """A ball that holds every position a frame's origin can take (fixed base only).

    The centre is where the frame's first moving joint sits (fixed in the world); the
    radius adds the length of every joint placement after it, the frame's offset, and
    the range of every prismatic joint of the chain. An upper bound, not the workspace.

    Args:
        model: The Pinocchio model.
        frame_id: The frame.
        lower, upper: Position limits per joint coordinate (nv,), ±inf where unlimited.

    Returns:
        ``(centre in [m], radius in [m])``, or ``None`` when unbounded (a floating base,
        an unlimited or mimic prismatic joint).
    """
    chain = [joint for joint in model.supports[model.frames[frame_id].parentJoint] if joint != 0]
    if not chain:
        return None
    radius = float(np.linalg.norm(model.frames[frame_id].placement.translation))
    for position, joint in enumerate(chain):
        kind = model.joints[joint].shortname().removeprefix("JointModel")
        if kind.startswith(("FreeFlyer", "Planar", "Spherical", "Mimic", "Translation")):
            return None
        if kind.startswith("P"):  # PX, PY, PZ, PrismaticUnaligned
            index = model.joints[joint].idx_v
            if not (np.isfinite(lower[index]) and np.isfinite(upper[index])):
                return None
            radius += float(upper[index] - lower[index])
        if position > 0:
            radius += float(np.linalg.norm(model.jointPlacements[joint].translation))
    first = chain[0]
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    centre = data.oMi[model.parents[first]] * model.jointPlacements[first]
    return centre.translation.tolist(), radius
