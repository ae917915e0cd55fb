"""Errors of a computation that cannot give a right answer: a non-finite result, a singular
mass matrix, a failing simulation or controller, a compilation, an identification, a
derivation too expensive, an optimisation.
"""

from __future__ import annotations

from robodyn.common.text import quoted
from robodyn.exceptions.base import RobodynError


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
        joints: Joints that move no mass (their whole subtree is massless), or with
            ``inertialess`` those whose motions together move no inertia at the state, if any.
        row: The state's row in a batch (0-based), or ``None`` for one state.
    """

    def __init__(self, robot: str, joints: list[str], *, inertialess: bool = False, row: int | None = None):
        self.robot = robot
        self.joints = list(joints)
        self.row = row
        moved = (
            "together move no inertia here (point masses, no rotational inertia behind them)" if inertialess else "move no mass"
        )
        reason = (
            f"joints {', '.join(repr(j) for j in self.joints)} {moved}" if self.joints else "the accelerations are not finite"
        )
        where = "" if row is None else f" at row {row} of the batch"
        super().__init__(f"robot {robot!r}: the mass matrix is singular{where}, so forward dynamics is undefined ({reason}).")


class SimulationError(RobodynError):
    """The simulated state stopped being finite.

    Attributes:
        time: Simulation time of the last finite state, in [s].
        step: Index of the step that diverged.
        joint: Name of the first joint whose position or velocity is not finite.
        advice: The likely cause and the remedy (default: a smaller ``dt``).
    """

    def __init__(self, time: float, step: int, joint: str, advice: str = "try a smaller dt"):
        self.time = time
        self.step = step
        self.joint = joint
        self.advice = advice
        super().__init__(f"simulation diverged at t = {time:.6g} s (step {step}): joint {joint!r} is no longer finite; {advice}.")


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


class OptimizationError(RobodynError):
    """The optimiser found no motion: IPOPT's status and, when it can be told, the limiting constraint.

    Attributes:
        robot: Robot name.
        status: IPOPT's return status.
        limiting: e.g. ``"the effort limit of 'shoulder'"`` ("" when it cannot be told).
    """

    def __init__(self, robot: str, status: str, limiting: str = ""):
        self.robot, self.status, self.limiting = robot, status, limiting
        because = f"; the limiting constraint is {limiting}" if limiting else ""
        super().__init__(f"no motion found for {quoted(robot)}: IPOPT stopped with {status}{because}.")
