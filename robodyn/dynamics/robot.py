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

from collections.abc import Sequence
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from robodyn.constraints import Constraint, from_equalities
from robodyn.dynamics import centroidal, configurations, constrained, derivatives, energies, frames, kinematics, mujoco_state
from robodyn.dynamics import regressor as identification
from robodyn.dynamics.configurations import PLACEHOLDER_LIMIT
from robodyn.dynamics.display import robot_html
from robodyn.dynamics.dofs import Dof, configuration_names, robot_dofs
from robodyn.dynamics.handle import ModelHandle
from robodyn.dynamics.joint_dynamics import friction_torque
from robodyn.dynamics.joints import JointInfo
from robodyn.dynamics.kernels import massless_joints
from robodyn.dynamics.mimic import MimicExpansion
from robodyn.dynamics.options import LoadOptions
from robodyn.exceptions import NonFiniteResultError, SingularMassMatrixError
from robodyn.urdf.sources import URDFSource
from robodyn.urdf.validation import URDFSpec


class Robot:
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
            SingularMassMatrixError: If ``M(q)`` is singular (massless moving bodies).
        """
        if self.massless_joints:  # M singular for every q: ABA's finite numbers would be wrong
            raise SingularMassMatrixError(self.name, self.massless_joints)
        try:
            return self.handle.calls.a(q, v, tau)
        except NonFiniteResultError:  # finite inputs, non-finite accelerations: only a singular M does that
            raise SingularMassMatrixError(self.name, self.massless_joints) from None

    def forward_dynamics_unchecked(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """:meth:`forward_dynamics` of one state without the boundary checks.

        For inner loops (simulation) whose inputs were checked once: float64 1-D arrays of
        the right sizes. A singular mass matrix gives non-finite values here (ABA), or a
        :class:`SingularMassMatrixError` for robots with mimic joints.
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

    # ----------------------------------------------------------------------------------
    # Derivatives (robodyn.dynamics.derivatives): q columns in the tangent space
    # ----------------------------------------------------------------------------------
    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂τ/∂q, ∂τ/∂v, ∂τ/∂a = M)`` of inverse dynamics (Pinocchio's analytical RNEA
        derivatives; :func:`robodyn.dynamics.derivatives.inverse_dynamics_derivatives`).

        Derivatives in ``q`` are along :meth:`integrate` (Pinocchio's convention: the
        floating base's six columns are its displacements in the base frame).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).

        Returns:
            Three arrays of shape (nv, nv) or (N, nv, nv), in SI units (torque per unit of
            the coordinate).
        """
        return derivatives.inverse_dynamics_derivatives(self.handle, q, v, a)

    def forward_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ = M⁻¹)`` of forward dynamics (Pinocchio's analytical ABA
        derivatives; :func:`robodyn.dynamics.derivatives.forward_dynamics_derivatives`).

        Derivatives in ``q`` are along :meth:`integrate`, as for
        :meth:`inverse_dynamics_derivatives`.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

        Returns:
            Three arrays of shape (nv, nv) or (N, nv, nv), in SI units.

        Raises:
            SingularMassMatrixError: If ``M(q)`` is singular (massless moving bodies).
        """
        return derivatives.forward_dynamics_derivatives(self.handle, q, v, tau)

    # ----------------------------------------------------------------------------------
    # Energies (robodyn.dynamics.energies)
    # ----------------------------------------------------------------------------------
    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
        """Kinetic energy ``½ vᵀ M(q) v`` in [J]: a float, or shape (N,) for a batch."""
        return energies.kinetic_energy(self.handle, q, v)

    def potential_energy(self, q: np.ndarray) -> float | np.ndarray:
        """Gravitational potential energy ``−Σ m_i gᵀ p_i`` in [J]: a float, or shape (N,).

        Zero when every centre of mass is at height zero (for the default gravity).
        """
        return energies.potential_energy(self.handle, q)

    # ----------------------------------------------------------------------------------
    # Kinematics (robodyn.dynamics.kinematics)
    # ----------------------------------------------------------------------------------
    @property
    def frame_names(self) -> list[str]:
        """Names of every frame: links, joints and fixed frames of the URDF."""
        return list(self.handle.frames)

    @property
    def frame_ids(self) -> dict[str, int]:
        """Pinocchio index of every frame, by name (a copy)."""
        return dict(self.handle.frames)

    def frame_id(self, frame: str) -> int:
        """Pinocchio index of a frame (link, joint or fixed frame) by name.

        Raises:
            FrameError: If the robot has no such frame (with the closest names).
        """
        return kinematics.frame_id(self.handle, frame)

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Position of a frame's origin in the world frame, shape (3,) or (N, 3), in [m]
        (:func:`robodyn.dynamics.kinematics.frame_position`)."""
        return kinematics.frame_position(self.handle, q, frame)

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Jacobian of a frame, shape (6, nv) or (N, 6, nv): linear rows then angular, in
        world-aligned axes at the frame's origin (:func:`robodyn.dynamics.kinematics.frame_jacobian`)."""
        return kinematics.frame_jacobian(self.handle, q, frame)

    def frame_bias_acceleration(self, q: np.ndarray, v: np.ndarray, frame: str) -> np.ndarray:
        """``J̇(q, v) v`` of a frame's origin, world axes, shape (3,), in [m/s²]
        (:func:`robodyn.dynamics.kinematics.frame_bias_acceleration`)."""
        return kinematics.frame_bias_acceleration(self.handle, q, v, frame)

    def wrench_torques(self, q: np.ndarray, frame: str, wrench: np.ndarray) -> np.ndarray:
        """Joint torques ``J(q)ᵀ w`` of a wrench (force [N], torque [N m], world axes) on a
        frame's origin, shape (nv,) (:func:`robodyn.dynamics.kinematics.wrench_torques`)."""
        return kinematics.wrench_torques(self.handle, q, frame, wrench)

    def integrate(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """The configuration reached from ``q`` along the velocity ``dq`` in unit time
        (:func:`robodyn.dynamics.kinematics.integrate`: SE(3) for a floating base)."""
        return kinematics.integrate(self.handle, q, dq)

    # ----------------------------------------------------------------------------------
    # Limits and configurations (robodyn.dynamics.configurations)
    # ----------------------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        """Lower position limits per degree of freedom, shape (nv,), in [rad] or [m].

        The six base coordinates of a floating base are unlimited (-inf).
        """
        return configurations.lower_limits(self.dofs)

    @property
    def upper_limits(self) -> np.ndarray:
        """Upper position limits per degree of freedom, shape (nv,), in [rad] or [m]."""
        return configurations.upper_limits(self.dofs)

    def neutral_configuration(self) -> np.ndarray:
        """The neutral configuration (zero joint positions, identity base), shape (nq,)."""
        return configurations.neutral_configuration(self.handle)

    def default_configuration(self) -> np.ndarray:
        """The neutral configuration clipped into the joint position limits, shape (nq,)
        (:func:`robodyn.dynamics.configurations.default_configuration`)."""
        return configurations.default_configuration(self.handle, self.dofs)

    def physical_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Position limits of the joints (floating base excluded), placeholders and empty
        ranges as ±inf: ``(lower, upper)``, each of shape (nv,) or (nv − 6,)
        (:func:`robodyn.dynamics.configurations.physical_limits`)."""
        return configurations.physical_limits(self.dofs)

    def floating_configuration(self, position, rpy, joints=None) -> np.ndarray:
        """A floating-base ``q`` (nq,) from the base position in [m], its roll, pitch, yaw
        in [rad] and the joint positions (default zeros)
        (:func:`robodyn.dynamics.configurations.floating_configuration`).

        Raises:
            InputError: For a fixed-base robot or wrong sizes.
        """
        return configurations.floating_configuration(self.handle, position, rpy, joints)

    def random_configuration(self, rng: np.random.Generator, count: int | None = None) -> np.ndarray:
        """Configurations drawn uniformly within the joint limits, in a physical range,
        shape (nq,) or (count, nq) (:func:`robodyn.dynamics.configurations.random_configuration`).

        Raises:
            InputError: If ``count`` is not a non-negative integer.
        """
        return configurations.random_configuration(self.handle, self.dofs, rng, count)

    # ----------------------------------------------------------------------------------
    # Identification (robodyn.dynamics.regressor)
    # ----------------------------------------------------------------------------------
    def regressor(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, friction: bool = False) -> np.ndarray:
        """The inertial-parameter regressor ``Y`` with ``Y @ inertial_parameters() == tau``.

        Per body (the links that move): m, m·c (3), inertia about the body origin in the
        body frame (Ixx, Ixy, Iyy, Ixz, Iyz, Izz); optional viscous and Coulomb friction
        columns per degree of freedom. See :func:`robodyn.dynamics.regressor.regressor`.

        Returns:
            Shape (nv, 10·n_bodies [+ 2·nv]) or (N, nv, …) for a batch.
        """
        return identification.regressor(self.handle, q, v, a, friction=friction)

    def inertial_parameters(self, *, friction: bool = False) -> np.ndarray:
        """The URDF's standard inertial parameters π, in :meth:`regressor`'s order."""
        return identification.inertial_parameters(self.handle, friction=friction)

    # ----------------------------------------------------------------------------------
    # Constraints (robodyn.dynamics.constrained; the rows: robodyn.constraints.algebra).
    # ``constraints=None``: the robot's own (:attr:`constraints`).
    # ----------------------------------------------------------------------------------
    @property
    def constraints(self) -> tuple[Constraint, ...]:
        """The robot's constraints: its file's (MJCF ``<equality>``), then ``load(constraints=)``'s."""
        return (*from_equalities(self.source.equalities), *self.options.constraints)

    def constrained_forward_dynamics(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, constraints: object = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(a, λ)`` of ``M a + C v + G = tau + Jᵀ λ``, ``J a + J̇ v = 0`` (contacts bilateral;
        ``λ`` least-norm for a redundant set), shapes (nv,), (m,) or (N, nv), (N, m)
        (:func:`robodyn.dynamics.constrained.forward_dynamics`)."""
        return constrained.forward_dynamics(self, q, v, tau, constraints)

    def contact_inverse_dynamics(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray, constraints: object = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(tau, λ)``: the least-norm ``λ`` that carries the unactuated coordinates, ``tau``
        the rest (:func:`robodyn.dynamics.constrained.contact_inverse_dynamics`)."""
        return constrained.contact_inverse_dynamics(self, q, v, a, constraints)

    def constraint_jacobian(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J(q)``, shape (m, nv) or (N, m, nv) (:func:`robodyn.dynamics.constrained.constraint_jacobian`)."""
        return constrained.constraint_jacobian(self, q, constraints)

    def constraint_drift(self, q: np.ndarray, v: np.ndarray, constraints: object = None) -> np.ndarray:
        """``J̇(q, v) v``, shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_drift`)."""
        return constrained.constraint_drift(self, q, v, constraints)

    def constraint_residual(self, q: np.ndarray, constraints: object = None) -> np.ndarray:
        """``Φ(q)`` in [m] / [rad], shape (m,) or (N, m) (:func:`robodyn.dynamics.constrained.constraint_residual`)."""
        return constrained.constraint_residual(self, q, constraints)

    def constraint_rank(self, q: np.ndarray, constraints: object = None) -> int:
        """Independent rows of the constraints at ``q`` (nq,) (:func:`robodyn.dynamics.constrained.constraint_rank`)."""
        return constrained.constraint_rank(self, q, constraints)

    # ----------------------------------------------------------------------------------
    # MuJoCo's state (robodyn.dynamics.mujoco_state)
    # ----------------------------------------------------------------------------------
    def to_mujoco(self, q: np.ndarray, v: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None) -> tuple:
        """MuJoCo's ``(qpos, qvel)`` of ``(q, v)``: joints by name in MuJoCo's order, ``ref``
        offsets, the free joint's w-first quaternion and world linear velocity. See
        :mod:`robodyn.dynamics.mujoco_state` (``joint_names``: MuJoCo's order, needed
        unless the robot was read from MJCF)."""
        return mujoco_state.to_mujoco(self, q, v, joint_names=joint_names)

    def from_mujoco(self, qpos: np.ndarray, qvel: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None) -> tuple:
        """robodyn's ``(q, v)`` of MuJoCo's ``(qpos, qvel)`` (the inverse of :meth:`to_mujoco`)."""
        return mujoco_state.from_mujoco(self, qpos, qvel, joint_names=joint_names)

    # ----------------------------------------------------------------------------------
    # Centroidal quantities (robodyn.dynamics.centroidal)
    # ----------------------------------------------------------------------------------
    def center_of_mass(self, q: np.ndarray) -> np.ndarray:
        """The moving bodies' centre of mass (a floating robot's: all of it) in [m], world
        axes, shape (3,) or (N, 3)
        (:func:`robodyn.dynamics.centroidal.center_of_mass`)."""
        return centroidal.center_of_mass(self.handle, q)

    def centroidal_momentum(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Linear [kg m/s] then angular momentum about the centre of mass [kg m²/s], world
        axes, shape (6,) or (N, 6) (:func:`robodyn.dynamics.centroidal.centroidal_momentum`)."""
        return centroidal.centroidal_momentum(self.handle, q, v)

    def centroidal_momentum_matrix(self, q: np.ndarray) -> np.ndarray:
        """``A_G(q)`` with ``h = A_G v``, shape (6, nv) or (N, 6, nv)
        (:func:`robodyn.dynamics.centroidal.centroidal_momentum_matrix`)."""
        return centroidal.centroidal_momentum_matrix(self.handle, q)


def joint_infos(model: pin.Model, spec: URDFSpec) -> list[JointInfo]:
    """The joints of ``model`` that have coordinates (mimic joints follow another joint and
    have none), in Pinocchio's order, with their URDF limits; a floating root joint is
    unlimited."""
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
