"""Exceptions raised by robodyn.

Every error robodyn raises on purpose derives from :class:`RobodynError`, so a caller (and
the CLI) can catch them all at once. Each subclass carries the offending values as
attributes and a one-sentence message naming the thing and the rule it broke.
"""

from __future__ import annotations

import contextlib
import sys
import warnings
from collections.abc import Iterator

from robodyn.common.text import printable, quoted


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Show each :class:`RobodynWarning` as one escaped stderr line.

    ``robodyn: warning: <message>`` instead of Python's two-line ``file:line: category``
    format, each problem once (robodyn and the reference may both find it); other warnings
    keep Python's format. The previous hook is restored on exit.
    """
    with warnings.catch_warnings():
        previous = warnings.showwarning
        shown: set[str] = set()

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, RobodynWarning):
                text = printable(message)
                problem = text.split(": ", 1)[-1]  # the same problem found by two loaders: once
                if problem not in shown:
                    shown.add(problem)
                    print(f"robodyn: warning: {text}", file=file or sys.stderr)
            else:
                previous(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield


class RobodynError(Exception):
    """Base class of every error robodyn raises on purpose.

    Its message is always one printable line: whatever a subclass puts into it (names
    from a URDF included) passes through :func:`printable`.
    """

    def __str__(self) -> str:
        return printable(super().__str__())


class RobodynWarning(UserWarning):
    """A legal but suspicious input that robodyn accepts (``strict=True`` refuses it).

    Example: a positive semi-definite inertia that breaks the triangle inequality, which
    Pinocchio, Drake, pybullet and urdfdom all load.
    """


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


class NonFiniteResultError(RobodynError, ArithmeticError):
    """Finite inputs gave a non-finite result (an overflow): refused, never returned.

    Attributes:
        robot: The robot's name.
        quantity: What overflowed (``"tau"``, ``"M"``, ...).
    """

    def __init__(self, robot: str, quantity: str):
        self.robot = robot
        self.quantity = quantity
        super().__init__(f"robot {quoted(robot)}: {quantity} overflowed to a non-finite value for finite inputs.")


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


class MissingExtraError(RobodynError, ImportError):
    """An optional dependency is not installed.

    Attributes:
        module: The module that could not be imported.
        extra: The robodyn extra that installs it.
        purpose: What it is needed for.
    """

    def __init__(self, module: str, extra: str, purpose: str):
        self.module = module
        self.extra = extra
        self.purpose = purpose
        super().__init__(
            f"{purpose} need {module!r}, which is not installed: the 'robodyn[{extra}]' extra "
            f"(pip install '.[{extra}]' in a clone of robodyn)."
        )


class OutputError(RobodynError, OSError):
    """An output file that robodyn refuses to write or cannot write; nothing was replaced.

    Attributes:
        path: The output path as given.
        reason: Why, e.g. ``"its folder does not exist"``.
    """

    def __init__(self, path: str, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"cannot write {quoted(path)}: {reason}.")

    def __str__(self) -> str:  # OSError would format its own way
        return printable(self.args[0])


class CompileError(RobodynError):
    """A robot the compiled engine cannot compile (a failed build, a controller with no C twin).

    Attributes:
        robot: The robot's name.
        reason: Why, in a few words.
    """

    def __init__(self, robot: str, reason: str):
        self.robot = robot
        self.reason = reason
        super().__init__(f"cannot compile robot {robot!r}: {reason}.")


class CompilerNotFoundError(CompileError):
    """No C compiler for the compiled engine (the Pinocchio path keeps working).

    Attributes:
        compiler: The compiler looked for (``$CC`` or ``cc``).
    """

    def __init__(self, compiler: str, detail: str | None = None):
        self.compiler = compiler
        extra = f" ({detail})" if detail else ""
        super().__init__(
            "<any>",
            f"no C compiler {compiler!r} found{extra}; install one (Debian/Ubuntu: apt-get install gcc, "
            "or set CC) or use the Pinocchio methods of robodyn.Robot",
        )


class IdentificationError(RobodynError):
    """System identification cannot give a trustworthy answer (a rank-deficient excitation,
    an unstable base-parameter set, a solver that did not converge, data of another robot).

    Attributes:
        robot: The robot's name.
        reason: What went wrong, with the offending numbers.
    """

    def __init__(self, robot: str, reason: str):
        self.robot = robot
        self.reason = reason
        super().__init__(f"robot {quoted(robot)}: {reason}.")


class DerivationTooExpensiveError(RobodynError):
    """A closed-form derivation estimated to take too long (the compact form does not).

    Attributes:
        robot: Robot name.
        joints: Number of joints.
        estimate_s: Estimated derivation time in [s].
        limit_s: The largest estimate accepted, in [s].
    """

    def __init__(self, robot: str, joints: int, estimate_s: float, limit_s: float):
        self.robot = robot
        self.joints = joints
        self.estimate_s = estimate_s
        self.limit_s = limit_s
        super().__init__(
            f"the closed form of {quoted(robot)} ({joints} joints) would take about {estimate_s:.3g} s to derive "
            f"(limit {limit_s:g} s); use form='compact'."
        )


class MissingToolError(RobodynError, OSError):
    """An external program a feature needs is not installed.

    Attributes:
        tool: The program, e.g. ``"pdflatex"``.
        purpose: What it was needed for.
    """

    def __init__(self, tool: str, purpose: str, hint: str = ""):
        self.tool = tool
        self.purpose = purpose
        super().__init__(f"{purpose} needs {tool}, which is not installed{'; ' + hint if hint else ''}.")


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


class JointLimitWarning(RobodynWarning):
    """A simulation or motion left a joint's position, velocity or effort limits.

    Attributes:
        violations: The violations (joint, quantity, first time, worst value, limit).
    """

    def __init__(self, message: str, violations: list | None = None):
        self.violations = list(violations or [])
        super().__init__(message)


class ControllerFailedError(SimulationError):
    """A controller raised a numerical error (a singular solve) during a simulation.

    Attributes:
        time: Simulation time of the step, in [s].
        step: Index of the step.
        joint: The joint with the largest speed at that state.
        speed: Its speed, in [rad/s] or [m/s].
        reason: The numerical error, e.g. ``"Singular matrix"``.
    """

    def __init__(self, time: float, step: int, joint: str, speed: float, reason: str):
        self.time = time
        self.step = step
        self.joint = joint
        self.speed = speed
        self.reason = reason
        RobodynError.__init__(
            self,
            f"simulation stopped at t = {time:.6g} s (step {step}): the controller failed ({reason}) "
            f"with joint {joint!r} at speed {speed:.3g}; try a smaller dt or gentler gains.",
        )


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


class ViewerError(RobodynError):
    """Viewing failed or was refused: a recording, a still or video, the browser, the live viewer.

    Attributes:
        reason: What went wrong, with the offending values.
    """

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(reason)


class SchedulerError(RobodynError):
    """A Dask scheduler that cannot be used (Dask missing, address unreachable).

    Attributes:
        scheduler: The address or ``local:N`` given.
        reason: Why.
    """

    def __init__(self, scheduler: str, reason: str):
        self.scheduler = scheduler
        self.reason = reason
        super().__init__(f"scheduler={quoted(scheduler)}: {reason}.")


class TypesettingError(RobodynError):
    """The TeX engine refused a document robodyn wrote.

    Attributes:
        reason: The engine's first error line.
    """

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"pdflatex failed on the equations: {reason}")


class OptimizationError(RobodynError):
    """The optimiser found no motion: IPOPT's status and, when it can be told, the limiting constraint.

    Attributes:
        robot: Robot name. status: IPOPT's return status. limiting: e.g. ``"the effort limit
        of 'shoulder'"`` ("" when it cannot be told).
    """

    def __init__(self, robot: str, status: str, limiting: str = ""):
        self.robot, self.status, self.limiting = robot, status, limiting
        because = f"; the limiting constraint is {limiting}" if limiting else ""
        super().__init__(f"no motion found for {quoted(robot)}: IPOPT stopped with {status}{because}.")
