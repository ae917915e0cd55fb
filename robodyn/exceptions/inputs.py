"""Errors and warnings about what a caller or a file gave: arguments, robot names, URDFs,
frames, trajectories, meshes, joint limits.
"""

from __future__ import annotations

from robodyn.common.text import printable, quoted
from robodyn.exceptions.base import RobodynError, RobodynWarning


class InputError(RobodynError, ValueError):
    """A numeric argument has the wrong shape, size or a non-finite value.

    Attributes:
        argument: Name of the offending argument, e.g. ``"q"``.
        expected: What was expected, e.g. ``"7 values"``.
        received: What was received, e.g. ``"6 values"``.
    """

    def __init__(self, argument: str, expected: str, received: str):
        self.argument = argument
        self.expected = expected
        self.received = received
        super().__init__(f"{argument} must be {expected}, got {received}.")


class UnknownRobotError(RobodynError, LookupError):
    """A robot name that is neither a file, URDF text, a zoo robot nor a generated robot.

    Attributes:
        name: The name that was asked for.
        suggestions: Known names close to it.
    """

    def __init__(self, name: str, suggestions: list[str] | None = None):
        self.name = name
        self.suggestions = list(suggestions or [])
        hint = f" (did you mean {', '.join(self.suggestions)}?)" if self.suggestions else ""
        super().__init__(
            f"unknown robot {quoted(name if len(name) <= 200 else name[:200] + '...')}: not a file, URDF text, zoo robot"
            f" or generated robot{hint}; 'robodyn list' shows the names."
        )


class URDFError(RobodynError, ValueError):
    """A URDF that cannot be read or describes a physically impossible robot.

    Attributes:
        source: Where the URDF came from (a path, a robot name or ``"<string>"``).
        element: The offending element, e.g. ``'link "l1"'``, or ``None``.
        rule: The rule that was broken.
    """

    def __init__(self, source: str, rule: str, element: str | None = None):
        self.source = source
        self.element = element
        self.rule = rule
        where = f"{source}: {element}: " if element else f"{source}: "
        super().__init__(where + rule)


class FrameError(RobodynError, KeyError):
    """A frame (link or joint) name that the robot does not have.

    Attributes:
        frame: The name asked for.
        robot: The robot's name.
    """

    def __init__(self, frame: str, robot: str, close: list[str] | None = None):
        self.frame = frame
        self.robot = robot
        self.close = list(close or [])
        hint = f" (did you mean {', '.join(quoted(name) for name in self.close)}?)" if self.close else ""
        super().__init__(f"robot {quoted(robot)} has no frame named {quoted(frame)}{hint}.")

    def __str__(self) -> str:  # KeyError would quote the message
        return printable(self.args[0])


class StaticFrameError(FrameError):
    """A task (target, payload, force) on a frame that no joint moves: it would do nothing.

    Attributes:
        robot: The robot's name.
        frame: The frame asked for.
        purpose: What the frame was for, e.g. ``"a payload"``.
        moving: Some frames that do move (hints).
    """

    def __init__(self, robot: str, frame: str, purpose: str, moving: list[str] | None = None):
        self.robot = robot
        self.frame = frame
        self.purpose = purpose
        self.moving = list(moving or [])
        self.close = self.moving
        hint = f" (moving frames: {', '.join(repr(name) for name in self.moving)})" if self.moving else ""
        Exception.__init__(
            self,
            f"robot {robot!r}: frame {frame!r} is fixed to the world (no joint moves it), so {purpose} on it would have no effect{hint}.",
        )


class AmbiguousEndEffectorError(FrameError):
    """A robot whose moving joints form several chains (legs, fingers): no default end effector.

    Attributes:
        robot: The robot's name.
        candidates: The tip of every chain.
    """

    def __init__(self, robot: str, candidates: list[str]):
        self.robot = robot
        self.frame = ""  # no frame was asked for
        self.candidates = list(candidates)
        self.close = self.candidates
        Exception.__init__(
            self,
            f"robot {robot!r} has {len(self.candidates)} chain tips and no default end effector: "
            f"name one (frame=...) of {', '.join(repr(name) for name in self.candidates)}.",
        )


class TrajectoryError(RobodynError, ValueError):
    """A trajectory or dataset file that cannot be used as it is.

    Attributes:
        source: The file (or ``"the trajectory"``).
        reason: What is wrong, naming the columns concerned.
        rows: First and last data row concerned (1-based), or ``None``.
    """

    def __init__(self, source: str, reason: str, rows: tuple[int, int] | None = None):
        self.source = source
        self.reason = reason
        self.rows = None if rows is None else (int(rows[0]), int(rows[1]))
        where = (
            ""
            if self.rows is None
            else (f", row {self.rows[0]}" if self.rows[0] == self.rows[1] else f", rows {self.rows[0]}-{self.rows[1]}")
        )
        super().__init__(f"{source}{where}: {reason}.")

    def __reduce__(self) -> tuple:  # crosses process boundaries (Dask workers) intact
        return (self.__class__, (self.source, self.reason, self.rows))


class JointLimitWarning(RobodynWarning):
    """A simulation or motion left a joint's position, velocity or effort limits.

    Attributes:
        violations: The violations (joint, quantity, first time, worst value, limit).
    """

    def __init__(self, message: str, violations: list | None = None):
        self.violations = list(violations or [])
        super().__init__(message)


class MeshPathError(RobodynError, ValueError):
    """A mesh path that leaves the model's folders, or is not a regular file.

    Attributes:
        filename: The mesh path as the URDF writes it.
        reason: Why it is refused.
    """

    def __init__(self, filename: str, reason: str):
        self.filename = filename
        self.reason = reason
        super().__init__(f"mesh {quoted(filename)} {reason}")


class MeshFileError(RobodynError):
    """A mesh file that cannot be drawn (not a regular file, too large, corrupt).

    Attributes:
        path: The mesh file.
        reason: Why it cannot be drawn.
    """

    def __init__(self, path: object, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"mesh {quoted(str(path))} {reason}")


class MeshWarning(RobodynWarning):
    """A mesh replaced by a placeholder in a drawing."""
