"""Exceptions raised by robodyn.

Every error robodyn raises on purpose derives from :class:`RobodynError`, so a caller (and
the CLI) can catch them all at once. Each subclass carries the offending values as
attributes and a one-sentence message naming the thing and the rule it broke.
"""

from __future__ import annotations


class RobodynError(Exception):
    """Base class of every error robodyn raises on purpose."""


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
            f"unknown robot {name!r}: not a file, URDF text, zoo robot or generated robot{hint}; 'robodyn list' shows the names."
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
        hint = f" (did you mean {', '.join(repr(name) for name in self.close)}?)" if self.close else ""
        super().__init__(f"robot {robot!r} has no frame named {frame!r}{hint}.")

    def __str__(self) -> str:  # KeyError would quote the message
        return self.args[0]


class NonFiniteResultError(RobodynError, ArithmeticError):
    """Finite inputs gave a non-finite result (an overflow): refused, never returned.

    Attributes:
        robot: The robot's name.
        quantity: What overflowed (``"tau"``, ``"M"``, ...).
    """

    def __init__(self, robot: str, quantity: str):
        self.robot = robot
        self.quantity = quantity
        super().__init__(f"robot {robot!r}: {quantity} overflowed to a non-finite value for finite inputs.")


class SingularMassMatrixError(RobodynError, ArithmeticError):
    """Forward dynamics asked of a robot whose mass matrix is singular.

    Attributes:
        joints: Joints that move no mass (their whole subtree is massless), if any.
    """

    def __init__(self, robot: str, joints: list[str]):
        self.robot = robot
        self.joints = list(joints)
        reason = (
            f"joints {', '.join(repr(j) for j in self.joints)} move no mass"
            if self.joints
            else "the accelerations are not finite"
        )
        super().__init__(f"robot {robot!r}: the mass matrix is singular, so forward dynamics is undefined ({reason}).")


class SimulationError(RobodynError):
    """The simulated state stopped being finite.

    Attributes:
        time: Simulation time of the last finite state, in [s].
        step: Index of the step that diverged.
        joint: Name of the first joint whose position or velocity is not finite.
    """

    def __init__(self, time: float, step: int, joint: str):
        self.time = time
        self.step = step
        self.joint = joint
        super().__init__(
            f"simulation diverged at t = {time:.6g} s (step {step}): joint {joint!r} is no longer finite; try a smaller dt."
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
