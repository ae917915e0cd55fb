"""The :class:`Robot`: a loaded model and its dynamics, computed by Pinocchio.

Conventions, stated once:
    - ``q`` has ``nq`` entries and ``v``, ``a``, ``tau`` have ``nv``, in the order of
      :attr:`Robot.joint_names`. For a fixed-base robot ``nq == nv``: a continuous joint's
      entry is its angle in [rad], not Pinocchio's (cos, sin) pair. A floating base adds
      the base pose first (position in [m], unit quaternion x, y, z, w; ``nq = nv + 1``)
      and the base twist in the base frame (linear in [m/s], angular in [rad/s]).
    - Joint positions are in [rad] (revolute, continuous) or [m] (prismatic), torques
      in [N m] or forces in [N].
    - Every method takes one state as 1-D arrays, or a trajectory as 2-D arrays with one
      state a row, and returns one result or a stack of results with a leading axis of
      length N accordingly.
    - The equations of motion are ``tau = M(q) a + C(q, v) v + G(q)``; ``C`` is
      Pinocchio's Coriolis matrix, which satisfies ``dM/dt = C + C^T``.

A Robot is made by composition: a :class:`~robodyn.dynamics.handle.ModelHandle` (the model,
per-thread data, the input boundary and the fast path) inside, and methods that delegate to
the functions of the handle in :mod:`~robodyn.dynamics.kinematics`,
:mod:`~robodyn.dynamics.configurations`, :mod:`~robodyn.dynamics.energies` and
:mod:`~robodyn.dynamics.regressor`.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from robodyn.dynamics import frames
from robodyn.dynamics.configurations import PLACEHOLDER_LIMIT
from robodyn.dynamics.display import robot_html
from robodyn.dynamics.dofs import Dof, configuration_names, robot_dofs
from robodyn.dynamics.handle import ModelHandle
from robodyn.dynamics.inertia_rank import refuse_singular, singular_error
from robodyn.dynamics.joint_dynamics import friction_torque
from robodyn.dynamics.joints import JointInfo
from robodyn.dynamics.kernels import massless_joints
from robodyn.dynamics.mimic import MimicExpansion
from robodyn.dynamics.options import LoadOptions
from robodyn.dynamics.robot_constraints import RobotConstraints
from robodyn.dynamics.robot_derivatives import RobotDerivatives
from robodyn.dynamics.robot_exchange import RobotExchange
from robodyn.dynamics.robot_kinematics import RobotKinematics
from robodyn.exceptions import NonFiniteResultError, SingularMassMatrixError
from robodyn.urdf.sources import URDFSource
from robodyn.urdf.validation import URDFSpec


class Robot(RobotDerivatives, RobotKinematics, RobotConstraints, RobotExchange):
    """A rigid-body robot and its dynamics (RNEA, CRBA, ABA through Pinocchio).

    Build one with :func:`robodyn.load`. The Pinocchio model is available as
    :attr:`model` for anything robodyn does not wrap. Kinematics (frames, Jacobians) are
    the functions of :mod:`robodyn.dynamics.kinematics`, limits and configurations
    (neutral, default, random) those of :mod:`robodyn.dynamics.configurations`, all
    applied to the robot's :attr:`handle`.

    A robot may be used from several threads at once: each thread gets its own Pinocchio
    data (see :mod:`robodyn.dynamics.handle`).

    Pickling and copies: a robot pickles by its source and its complete load options
    (:attr:`options`), never by Pinocchio pointers, and unpickling builds it again once
    per process (:func:`robodyn.dynamics.loading.restore`). A robot is not changed by
    anything robodyn does, so ``copy.copy(robot)`` and ``copy.deepcopy(robot)`` return the
    robot itself (objects holding a robot copy cheaply and share it); for an independent
    robot, e.g. to edit its Pinocchio model by hand, use
    :func:`robodyn.dynamics.loading.rebuild`.

    Attributes:
        name: Robot name.
        handle: The model handle the methods delegate to (model, per-thread data, input
            checks, fast path); pass it to the functions of the modules above.
        model: The Pinocchio model.
        spec: The validated URDF (links, joints, inertials).
        source: Where the URDF came from (:attr:`urdf` is its text); copies and edits of
            the robot are built from it (:func:`robodyn.dynamics.loading.rebuild`).
        options: How it was built: every option of :func:`robodyn.load`.
        floating_base: Whether the root is a free-flyer joint.
        nq, nv: Sizes of a configuration and of a velocity.
        mimic: For robots with mimic joints, the model with every joint independent and the
            map to it (Pinocchio supports mimic joints in RNEA and CRBA but not everywhere).
        joints: The joints with coordinates (root joint first), with their limits.
        joint_names: Their names: the order of ``q``, ``v``, ``a``, ``tau``.
        dofs: One record per degree of freedom (name, joint, kind, units, limits), length nv.
        configuration_names: A name for each entry of ``q`` (length nq; a floating base's
            are ``base.x`` … ``base.qw``).
    """

    def __init__(
        self,
        model: pin.Model,
        *,
        spec: URDFSpec,
        source: URDFSource,
        options: LoadOptions,
        name: str,
        mimic: MimicExpansion | None = None,
    ):
        self.handle = ModelHandle(model, name=name, floating_base=options.floating_base, mimic=mimic, threads=options.threads)
        self.name = name
        self.model = model
        self.spec = spec
        self.source = source
        self.options = options
        self.floating_base = options.floating_base
        self.mimic = mimic
        self.nq: int = model.nq
        self.nv: int = model.nv
        self.joints: list[JointInfo] = joint_infos(model, spec)
        self.joint_names: list[str] = [joint.name for joint in self.joints]
        self.dofs: tuple[Dof, ...] = robot_dofs(
            self.joints, damping=model.damping, friction=model.friction, armature=model.armature, actuated=source.actuated
        )
        self.configuration_names: list[str] = configuration_names(self.joints)

    @property
    def data(self) -> pin.Data:
        """This thread's Pinocchio data for :attr:`model` (created on first use)."""
        return self.handle.data

    def validate(self, **named: object) -> tuple[list[np.ndarray], bool]:
        """Check state arguments by name (``q`` has nq entries, the others nv); see
        :meth:`robodyn.dynamics.handle.ModelHandle.validate`.

        Returns:
            The arguments as float64 arrays, and whether they are a batch (2-D).

        Raises:
            InputError: Naming the argument.
        """
        return self.handle.validate(**named)

    @property
    def urdf(self) -> str:
        """The URDF text the robot was built from (generated robots included)."""
        return self.source.text

    @property
    def source_path(self) -> Path | None:
        """The URDF file, if the robot came from one."""
        return self.source.path

    @property
    def package_dirs(self) -> tuple[Path, ...]:
        """Folders under which ``package://`` mesh paths resolve."""
        return self.source.package_dirs

    @property
    def threads(self) -> int:
        """Native threads used for batches of states."""
        return self.handle.parallel.threads

    def __repr__(self) -> str:
        return f"<Robot {self.name!r}: nq={self.nq}, nv={self.nv}, joints={self.joint_names}>"

    def __copy__(self) -> Robot:
        """The robot itself (see the class docstring)."""
        return self

    def __deepcopy__(self, memo: dict) -> Robot:
        """The robot itself (see the class docstring; ``rebuild`` makes an independent one)."""
        return self

    def _repr_html_(self) -> str:
        """The robot as an HTML table in notebooks (:func:`robodyn.dynamics.display.robot_html`)."""
        return robot_html(self)

    # ----------------------------------------------------------------------------------
    # Properties of the model
    # ----------------------------------------------------------------------------------
    @property
    def gravity_vector(self) -> np.ndarray:
        """Gravity acceleration in the world frame, shape (3,), in [m/s²]."""
        return self.model.gravity.linear.copy()

    @property
    def end_effector(self) -> str:
        """The frame tasks refer to by default: the tip of the chain the last moving joint
        drives (see :mod:`robodyn.dynamics.frames` for the rule; a link named
        ``end_effector`` that moves is taken as given).

        Raises:
            AmbiguousEndEffectorError: For robots with several chains (legs, fingers, two
                arms): the message lists the tips to choose from.
        """
        return frames.default_end_effector(self.model, self.name)

    def task_frame(self, frame: str | None, purpose: str) -> str:
        """A frame for a task, checked: ``frame`` (default :attr:`end_effector`) must exist
        and some joint must move it.

        Args:
            frame: Link or joint name; ``None`` for the default end effector.
            purpose: What the frame is for, for the message (e.g. ``"a payload"``).

        Raises:
            FrameError: Unknown frame. StaticFrameError: no joint moves it.
            AmbiguousEndEffectorError: No ``frame`` and no default end effector.
        """
        name = self.end_effector if frame is None else frame
        frames.require_moving(self.model, self.name, name, self.frame_id(name), purpose)
        return name

    @property
    def joint_damping(self) -> np.ndarray:
        """Viscous damping b per degree of freedom, shape (nv,), in [N m s/rad] or [N s/m]
        (joint torque ``−b v``; 0 for a floating base's six; see
        :mod:`robodyn.dynamics.joint_dynamics`)."""
        return np.array([dof.damping for dof in self.dofs])

    @property
    def joint_friction(self) -> np.ndarray:
        """Coulomb friction f per degree of freedom, shape (nv,), in [N m] or [N] (the
        torque ``−f sign(v)`` while sliding, up to ``±f`` at rest; 0 for a floating base's six)."""
        return np.array([dof.friction for dof in self.dofs])

    @property
    def joint_armature(self) -> np.ndarray:
        """Armature (rotor inertia reflected to the joint) per degree of freedom, shape
        (nv,), in [kg m²] or [kg]: on the diagonal of :meth:`mass_matrix` (0 for a
        floating base's six)."""
        return np.array([dof.armature for dof in self.dofs])

    @cached_property
    def link_masses(self) -> dict[str, float]:
        """Mass of every URDF link that has one, in [kg]."""
        return {name: inertial.mass for name, inertial in self.spec.links.items() if inertial is not None}

    @cached_property
    def massless_joints(self) -> list[str]:
        """Joints whose whole subtree has no mass (and a massless floating root carrying one
        joint): they make ``M(q)`` singular."""
        return massless_joints(self.model)

    @property
    def total_mass(self) -> float:
        """Total mass of the robot in [kg]."""
        return float(sum(self.link_masses.values()))

    # ----------------------------------------------------------------------------------
    # Dynamics: each quantity is a kernel of the handle (robodyn.dynamics.kernels), which
    # ModelHandle.evaluate runs on the raw arguments first; anything doubtful goes through
    # the full boundary check.
    # ----------------------------------------------------------------------------------
    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, joint_friction: bool = False) -> np.ndarray:
        """Joint torques ``tau = M(q) a + C(q, v) v + G(q)`` (RNEA; ``M`` includes the
        joints' armature, :attr:`joint_armature`).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).
            joint_friction: Add the torques the joints' friction takes,
                ``b v + f sign(v)`` (:attr:`joint_damping`, :attr:`joint_friction`), with
                ``sign(0) = 0``: at rest the Coulomb part is left out, since what a joint at
                rest needs is anything within ``±f``. Default: the rigid-body torques.

        Returns:
            Torques in [N m] / [N], shape (nv,) or (N, nv).
        """
        tau = self.handle.calls.tau(q, v, a)
        if joint_friction:
            tau = tau - friction_torque(self.joint_damping, self.joint_friction, np.asarray(v, dtype=float))
        return tau

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint accelerations ``a = M(q)⁻¹ (tau − C(q, v) v − G(q))`` (ABA).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

        Returns:
            Accelerations, shape (nv,) or (N, nv).

        Raises:
            SingularMassMatrixError: If ``M(q)`` is singular: massless moving bodies, or joints
                that together move no inertia at ``q`` (named, with the row of a batch).
        """
        if self.massless_joints:  # M singular for every q: ABA's finite numbers would be wrong
            raise SingularMassMatrixError(self.name, self.massless_joints)
        try:
            a = self.handle.calls.a(q, v, tau)
        except (NonFiniteResultError, SingularMassMatrixError):  # finite inputs: only a singular M does that
            raise singular_error(self, q) from None
        refuse_singular(self, q, a)  # ABA's pivot a round-off? (M's rank looked at only for huge a)
        return a

    def forward_dynamics_unchecked(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """:meth:`forward_dynamics` of one state without the boundary checks.

        For inner loops (simulation) whose inputs were checked once: float64 1-D arrays of
        the right sizes. A singular mass matrix gives non-finite values here (ABA), or a
        :class:`SingularMassMatrixError` for robots with mimic joints.

        Args:
            q: Configuration, float64, shape (nq,), in [rad] / [m].
            v: Velocity, float64, shape (nv,), in [rad/s] / [m/s].
            tau: Torques, float64, shape (nv,), in [N m] / [N].
        """
        return self.handle.kernels.a.single(q, v, tau)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space inertia matrix ``M(q)`` (CRBA), symmetric.

        Args:
            q: Configuration, shape (nq,) or (N, nq).

        Returns:
            Shape (nv, nv) or (N, nv, nv), in [kg m²] / [kg].
        """
        return self.handle.calls.M(q)

    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal matrix ``C(q, v)``, with ``dM/dt = C + Cᵀ``.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).

        Returns:
            Shape (nv, nv) or (N, nv, nv).
        """
        handle = self.handle
        return handle.evaluate(handle.kernels.C, q, v)

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """Generalised gravity ``G(q)``: the torques that hold the robot still.

        Args:
            q: Configuration, shape (nq,) or (N, nq).

        Returns:
            Shape (nv,) or (N, nv), in [N m] / [N].
        """
        return self.handle.calls.G(q)

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``: the torques at zero acceleration.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).

        Returns:
            Shape (nv,) or (N, nv), in [N m] / [N].
        """
        return self.handle.calls.nle(q, v)


def joint_infos(model: pin.Model, spec: URDFSpec) -> list[JointInfo]:
    """The joints of ``model`` that have coordinates (mimic joints follow another joint and
    have none), in Pinocchio's order, with their URDF limits; a floating root joint is
    unlimited.

    Args:
        model: The robot's Pinocchio model.
        spec: The validated URDF the model was built from (its joints' limits).
    """
    infos = []
    for joint_id in range(1, model.njoints):
        if model.joints[joint_id].nv == 0:  # mimic joints follow another joint
            continue
        name = model.names[joint_id]
        if name in spec.joints:
            joint = spec.joints[name]
            infos.append(JointInfo(name, joint.type, joint.lower, joint.upper, joint.effort, joint.velocity))
        else:
            infos.append(JointInfo(name, "floating", -np.inf, np.inf, np.inf, np.inf))
    return infos


__all__ = ["PLACEHOLDER_LIMIT", "Dof", "JointInfo", "LoadOptions", "Robot", "joint_infos"]
