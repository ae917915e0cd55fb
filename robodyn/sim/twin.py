"""What a controller's compiled twin needs, shared by the controllers that own one.

Each controller of :mod:`robodyn.sim.control` and :mod:`robodyn.sim.operational_space` that
the C loop can run has two methods (the protocol
:class:`robodyn.compiled.controllers.HasTwin`): ``twin_refusal()``, why it has no twin now
(``None``: it has one), and ``compiled()``, the twin on its own model compiled. These
helpers give the refusals every such controller shares; the code generator is imported
only when a twin is made.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import CompileError

if TYPE_CHECKING:
    from robodyn.compiled.robot import CompiledRobot


def fixed_base_only(controller: object) -> bool:
    """Whether the controller's twin models fixed bases only (its class's ``twin_fixed_base``:
    the frame laws' compiled kinematics and LQR).

    Args:
        controller: The controller.
    """
    return bool(getattr(type(controller), "twin_fixed_base", False))


def law_refusal(controller: object, owner: type) -> str | None:
    """Why ``controller`` (an instance of ``owner`` or a subclass) has no twin: a subclass
    that changes the law (its ``__call__``), or, for a twin of fixed bases only
    (:func:`fixed_base_only`), a floating model; ``None`` when it has one.

    Args:
        controller: The controller.
        owner: The class whose law the twin computes.
    """
    if type(controller).__call__ is not owner.__call__:
        return f"{type(controller).__name__} changes {owner.__name__}'s law; its compiled twin is {owner.__name__}'s"
    model = getattr(controller, "model", None)
    if fixed_base_only(controller) and isinstance(model, Robot) and model.floating_base:
        return f"it has a floating base; {owner.__name__} compiles for fixed-base robots"
    return None


def compiled_model(model: Robot, refusal: str | None) -> CompiledRobot:
    """A controller's own model, compiled (loading the code generator), after its refusal.

    Args:
        model: The controller's model of the robot.
        refusal: Why the controller has no twin (``None``: it has one).

    Raises:
        CompileError: With the refusal, when there is one.
    """
    if refusal is not None:
        raise CompileError(model.name, refusal)
    from robodyn.compiled.robot import compile

    return compile(model)


def viscous_compensation(model: Robot, compensate: bool, v: np.ndarray) -> np.ndarray | float:
    """The torque ``b ∘ v`` that cancels the joints' viscous damping (the model's
    :attr:`~robodyn.Robot.joint_damping`, shape (nv,) like ``v``), or 0 when ``compensate`` is
    off; the Coulomb term is never compensated (its sign switches at rest).

    Args:
        model: The controller's model of the robot.
        compensate: The controller's ``compensate_damping``.
        v: Joint velocities, shape (nv,), in [rad/s] or [m/s].
    """
    return model.joint_damping * v if compensate else 0.0


def viscous_params(model: Robot, compensate: bool, joints: int) -> np.ndarray | None:
    """The damping vector a compiled twin adds as ``b ∘ v`` (the last ``joints`` entries of the
    model's :attr:`~robodyn.Robot.joint_damping`: a floating base's joints), ``None`` when off.

    Args:
        model: The controller's model of the robot.
        compensate: The controller's ``compensate_damping``.
        joints: The law's coordinates (``nv``, or a floating base's ``nv − 6`` joints).
    """
    return np.array(model.joint_damping[model.nv - joints :], dtype=float) if compensate else None


def compensate(law: object, joint_friction: bool) -> None:
    """Make a model-based law (computed torque, task space, operational space, impedance,
    hybrid force/motion, the whole-body QP ``Stand`` or its recording wrapper) compensate the
    joints' viscous damping exactly when the run applies it.

    Args:
        law: The run's controller (others are left as they are).
        joint_friction: Whether the run applies the joints' damping (``simulate``'s option).
    """
    if hasattr(law, "compensate_damping"):
        law.compensate_damping = joint_friction
