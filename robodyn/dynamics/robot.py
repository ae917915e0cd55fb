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
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from robodyn.dynamics import frames
from robodyn.dynamics.batch import ParallelRunner
from robodyn.dynamics.configurations import PLACEHOLDER_LIMIT, ConfigurationSpace
from robodyn.dynamics.dofs import Dof, configuration_names, robot_dofs
from robodyn.dynamics.handle import per_state
from robodyn.dynamics.joints import JointInfo
from robodyn.dynamics.kinematics import Kinematics
from robodyn.dynamics.mimic import MimicExpansion
from robodyn.exceptions import NonFiniteResultError, SingularMassMatrixError
from robodyn.urdf.sources import URDFSource
from robodyn.urdf.validation import URDFSpec


@dataclass(frozen=True)
class LoadOptions:
    """How a robot was built from its source (what :func:`robodyn.load` was given).

    Attributes:
        floating_base: Whether the root got a free-flyer joint.
        gravity: Gravity in the world frame, in [m/s²].
        check_inertia: Whether impossible inertias on moving links were refused.
        threads: Native threads for batches (``None``: every available core).
        strict: Whether warnings of the validator were treated as errors.
    """

    floating_base: bool
    gravity: tuple[float, float, float]
    check_inertia: bool = True
    threads: int | None = None
    strict: bool = False


class Robot(Kinematics, ConfigurationSpace):
    """A rigid-body robot and its dynamics (RNEA, CRBA, ABA through Pinocchio).

    Build one with :func:`robodyn.load`. The Pinocchio model is available as
    :attr:`model` for anything robodyn does not wrap. Kinematics (frames, Jacobians) come
    from :class:`~robodyn.dynamics.kinematics.Kinematics`, limits and configurations
    (neutral, default, random) from :class:`~robodyn.dynamics.configurations.ConfigurationSpace`.

    A robot may be used from several threads at once: each thread gets its own Pinocchio
    data (see :mod:`robodyn.dynamics.handle`).

    Attributes:
        name: Robot name.
        model: The Pinocchio model.
        spec: The validated URDF (links, joints, inertials).
        source: Where the URDF came from (:attr:`urdf` is its text); copies and edits of
            the robot are built from it (:func:`robodyn.dynamics.loading.rebuild`).
        options: How it was built (floating base, gravity, inertia check, threads).
        floating_base: Whether the root is a free-flyer joint.
        mimic: For robots with mimic joints, the model with every joint independent and the
            map to it (Pinocchio supports mimic joints in RNEA and CRBA but not everywhere).
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
        super().__init__(model, name=name, floating_base=options.floating_base)
        self.spec = spec
        self.source = source
        self.options = options
        self.mimic = mimic
        self.joints: list[JointInfo] = self._joint_infos()
        self.joint_names: list[str] = [joint.name for joint in self.joints]
        #: One record per degree of freedom (name, joint, kind, units, limits), length nv.
        self.dofs: tuple[Dof, ...] = robot_dofs(self.joints)
        #: A name for each entry of ``q`` (length nq; a floating base's are ``base.x`` … ``base.qw``).
        self.configuration_names: list[str] = configuration_names(self.joints)
        self._parallel = ParallelRunner(model, threads=options.threads)
        self._kernels.update(self._dynamics_kernels())
        self._lower_triangle = np.tri(self.nv, self.nv, -1, dtype=bool)

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
        return self._parallel.threads

    def __repr__(self) -> str:
        return f"<Robot {self.name!r}: nq={self.nq}, nv={self.nv}, joints={self.joint_names}>"

    def __reduce__(self) -> tuple:
        """Pickle by source and options; unpickling rebuilds the robot once per process
        (:func:`robodyn.dynamics.pickling.restore`)."""
        from robodyn.dynamics.pickling import restore

        return restore, (self.source, self.options)

    def _joint_infos(self) -> list[JointInfo]:
        infos = []
        for joint_id in range(1, self.model.njoints):
            joint = self.model.joints[joint_id]
            if joint.nv == 0:  # mimic joints follow another joint
                continue
            name = self.model.names[joint_id]
            if name in self.spec.joints:
                urdf_joint = self.spec.joints[name]
                infos.append(
                    JointInfo(name, urdf_joint.type, urdf_joint.lower, urdf_joint.upper, urdf_joint.effort, urdf_joint.velocity)
                )
            else:
                infos.append(JointInfo(name, "floating", -np.inf, np.inf, np.inf, np.inf))
        return infos

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

    @cached_property
    def link_masses(self) -> dict[str, float]:
        """Mass of every URDF link that has one, in [kg]."""
        return {name: inertial.mass for name, inertial in self.spec.links.items() if inertial is not None}

    @cached_property
    def massless_joints(self) -> list[str]:
        """Joints whose whole subtree has no mass: they make ``M(q)`` singular."""
        subtree_mass = [self.model.inertias[i].mass for i in range(self.model.njoints)]
        for joint_id in range(self.model.njoints - 1, 0, -1):
            subtree_mass[self.model.parents[joint_id]] += subtree_mass[joint_id]
        return [self.model.names[i] for i in range(1, self.model.njoints) if subtree_mass[i] <= 0 and self.model.joints[i].nv > 0]

    @property
    def total_mass(self) -> float:
        """Total mass of the robot in [kg]."""
        return float(sum(self.link_masses.values()))

    # ----------------------------------------------------------------------------------
    # Dynamics. Each method asks ModelHandle._evaluate for its quantity, whose one-state
    # and (where Pinocchio has one) parallel batch function _dynamics_kernels set up once:
    # the fast path tries Pinocchio on the raw arguments first, anything doubtful goes
    # through the full boundary check.
    # ----------------------------------------------------------------------------------
    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Joint torques ``tau = M(q) a + C(q, v) v + G(q)`` (RNEA).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).

        Returns:
            Torques in [N m] / [N], shape (nv,) or (N, nv).
        """
        return self._evaluate("tau", ("q", "v", "a"), q, v, a)

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
        try:
            return self._evaluate("a", ("q", "v", "tau"), q, v, tau)
        except NonFiniteResultError:  # finite inputs, non-finite accelerations: only a singular M does that
            raise SingularMassMatrixError(self.name, self.massless_joints) from None

    def forward_dynamics_unchecked(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """:meth:`forward_dynamics` of one state without the boundary checks.

        For inner loops (simulation) whose inputs were checked once: float64 1-D arrays of
        the right sizes. A singular mass matrix gives non-finite values here (ABA), or a
        :class:`SingularMassMatrixError` for robots with mimic joints.
        """
        if self.mimic is not None:
            return self._solve_dynamics(q, v, tau)
        return pin.aba(self.model, self.data, q, v, tau)

    def _solve_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``M⁻¹ (tau − C v − G)`` by a linear solve (for models ABA cannot take)."""
        mass = self._mass_matrix(q)
        rhs = tau - pin.nonLinearEffects(self.model, self.data, q, v)
        try:
            return np.linalg.solve(mass, rhs)
        except np.linalg.LinAlgError:
            raise SingularMassMatrixError(self.name, self.massless_joints) from None

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space inertia matrix ``M(q)`` (CRBA), symmetric.

        Args:
            q: Configuration, shape (nq,) or (N, nq).

        Returns:
            Shape (nv, nv) or (N, nv, nv), in [kg m²] / [kg].
        """
        return self._evaluate("M", ("q",), q)

    def _mass_matrix(self, q: np.ndarray) -> np.ndarray:
        # Upper triangle only. With a mimic joint between two free joints, Pinocchio 4.1's
        # crba in its default LOCAL convention accumulates into data from call to call;
        # the WORLD convention does not (tests/test_nondegenerate.py, mimic_tree).
        if self.mimic is None:
            mass = pin.crba(self.model, self.data, q)
        else:
            mass = pin.crba(self.model, self.data, q, pin.Convention.WORLD)
        np.copyto(mass, mass.T, where=self._lower_triangle)
        return mass

    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal matrix ``C(q, v)``, with ``dM/dt = C + Cᵀ``.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).

        Returns:
            Shape (nv, nv) or (N, nv, nv).
        """
        return self._evaluate("C", ("q", "v"), q, v)

    def _coriolis(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self.mimic is not None:  # computeCoriolisMatrix mishandles mimic joints
            expansion = self.mimic
            with np.errstate(invalid="ignore"):  # inf inputs: the checks after report them
                full = pin.computeCoriolisMatrix(expansion.model, expansion.data, expansion.q(q), expansion.selection @ v)
                return expansion.selection.T @ full @ expansion.selection
        return pin.computeCoriolisMatrix(self.model, self.data, q, v)

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """Generalised gravity ``G(q)``: the torques that hold the robot still.

        Args:
            q: Configuration, shape (nq,) or (N, nq).

        Returns:
            Shape (nv,) or (N, nv), in [N m] / [N].
        """
        return self._evaluate("G", ("q",), q)

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``: the torques at zero acceleration.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).

        Returns:
            Shape (nv,) or (N, nv), in [N m] / [N].
        """
        return self._evaluate("C v + G", ("q", "v"), q, v)

    def _dynamics_kernels(self) -> dict:
        """One-state and batch functions of each quantity, for :meth:`_evaluate` (built once)."""
        model, data, run = self.model, self._data.get, self._parallel.run

        def gravity_batch(q: np.ndarray) -> np.ndarray:
            zeros = np.zeros((q.shape[0], self.nv))
            return run(pin.rneaInParallel, q, zeros, zeros)

        forward: tuple[Callable[..., np.ndarray], Callable[..., np.ndarray] | None] = (
            (lambda q, v, tau: pin.aba(model, data(), q, v, tau), lambda q, v, tau: run(pin.abaInParallel, q, v, tau))
            if self.mimic is None
            else (self._solve_dynamics, None)  # Pinocchio's ABA refuses mimic joints (abaInParallel crashes on them)
        )
        return {
            "tau": (lambda q, v, a: pin.rnea(model, data(), q, v, a), lambda q, v, a: run(pin.rneaInParallel, q, v, a)),
            "a": forward,
            "M": (self._mass_matrix, None),
            "C": (self._coriolis, None),
            "G": (lambda q: pin.computeGeneralizedGravity(model, data(), q), gravity_batch),
            "C v + G": (
                lambda q, v: pin.nonLinearEffects(model, data(), q, v),
                lambda q, v: run(pin.rneaInParallel, q, v, np.zeros_like(v)),
            ),
        }

    # ----------------------------------------------------------------------------------
    # Energies
    # ----------------------------------------------------------------------------------
    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
        """Kinetic energy ``½ vᵀ M(q) v`` in [J]: a float, or shape (N,) for a batch."""
        (q, v), batch = self.validate(q=q, v=v)
        # From the mass matrix rather than computeKineticEnergy, which refuses mimic joints.
        energy = per_state(lambda qi, vi: np.array(0.5 * vi @ self._mass_matrix(qi) @ vi), q, v)
        energy = self._finite(np.asarray(energy), "kinetic energy")
        return energy if batch else float(energy)

    def potential_energy(self, q: np.ndarray) -> float | np.ndarray:
        """Gravitational potential energy ``−Σ m_i gᵀ p_i`` in [J]: a float, or shape (N,).

        Zero when every centre of mass is at height zero (for the default gravity).
        """
        (q,), batch = self.validate(q=q)
        # computePotentialEnergy refuses mimic joints: use the expanded model for those.
        if self.mimic is None:
            energy = per_state(lambda qi: np.array(pin.computePotentialEnergy(self.model, self.data, qi)), q)
        else:
            mimic = self.mimic
            energy = per_state(lambda qi: np.array(pin.computePotentialEnergy(mimic.model, mimic.data, mimic.q(qi))), q)
        energy = self._finite(np.asarray(energy), "potential energy")
        return energy if batch else float(energy)

    # ----------------------------------------------------------------------------------
    # Identification (robodyn.dynamics.regressor)
    # ----------------------------------------------------------------------------------
    def regressor(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, friction: bool = False) -> np.ndarray:
        """The inertial-parameter regressor ``Y`` with ``Y @ inertial_parameters() == tau``.

        Per body (the links that move): m, m·c (3), inertia about the body origin in the
        body frame (Ixx, Ixy, Iyy, Ixz, Iyz, Izz); optional viscous and Coulomb friction
        columns per joint. See :func:`robodyn.dynamics.regressor.regressor`.

        Returns:
            Shape (nv, 10·n_bodies [+ 2·nv]) or (N, nv, …) for a batch.
        """
        from robodyn.dynamics.regressor import regressor

        return regressor(self, q, v, a, friction=friction)

    def inertial_parameters(self, *, friction: bool = False) -> np.ndarray:
        """The URDF's standard inertial parameters π, in :meth:`regressor`'s order."""
        from robodyn.dynamics.regressor import inertial_parameters

        return inertial_parameters(self, friction=friction)

    def _repr_html_(self) -> str:
        """The robot as an HTML table in notebooks (:func:`robodyn.dynamics.display.robot_html`)."""
        from robodyn.dynamics.display import robot_html

        return robot_html(self)


__all__ = ["PLACEHOLDER_LIMIT", "Dof", "JointInfo", "LoadOptions", "Robot"]
