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

import math
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from robodyn.common.inputs import as_states
from robodyn.exceptions import FrameError, InputError, RobodynError, SingularMassMatrixError
from robodyn.urdf.validation import URDFSpec

#: Largest accepted deviation of a floating base's quaternion norm from 1.
QUATERNION_TOLERANCE = 1e-6
#: What Pinocchio raises for arguments it refuses (wrong size, type, unsupported joint).
_PINOCCHIO_ERRORS = (TypeError, ValueError, RuntimeError)
_isfinite = math.isfinite


@dataclass(frozen=True)
class JointInfo:
    """One degree of freedom of a robot.

    Attributes:
        name: Joint name in the URDF.
        type: ``"revolute"``, ``"continuous"``, ``"prismatic"`` or ``"floating"``.
        lower, upper: Position limits in [rad] or [m] (±inf when unlimited).
        effort: Effort limit in [N m] or [N] (inf when not given).
        velocity: Velocity limit in [rad/s] or [m/s] (inf when not given).
    """

    name: str
    type: str
    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass
class MimicExpansion:
    """The map from a robot with mimic joints to the same robot with every joint free.

    ``q_full = q_selection @ q + offset`` and ``v_full = selection @ v`` (the mimic relation
    ``q_mimic = multiplier * q_source + offset`` is linear), so ``M = Sᵀ M_full S`` and
    ``C = Sᵀ C_full S``.

    Attributes:
        model: The Pinocchio model with mimic joints as independent joints.
        selection: Shape (nv_full, nv).
        offset: Shape (nq_full,).
        q_selection: Shape (nq_full, nq) (differs from ``selection`` with a floating base).
    """

    model: pin.Model
    selection: np.ndarray
    offset: np.ndarray
    q_selection: np.ndarray

    def __post_init__(self) -> None:
        self.data = self.model.createData()

    def q(self, q: np.ndarray) -> np.ndarray:
        """Configuration of the expanded model."""
        return self.q_selection @ q + self.offset


class Robot:
    """A rigid-body robot and its dynamics (RNEA, CRBA, ABA through Pinocchio).

    Build one with :func:`robodyn.load`. The Pinocchio model is available as
    :attr:`model` for anything robodyn does not wrap.

    Attributes:
        name: Robot name.
        urdf: The URDF text it was built from (generated robots included).
        model: The Pinocchio model.
        spec: The validated URDF (links, joints, inertials).
        floating_base: Whether the root is a free-flyer joint.
        source_path: The URDF file, if it came from one.
        package_dirs: Folders under which ``package://`` mesh paths resolve.
        mimic: For robots with mimic joints, the model with every joint independent and the
            map to it (Pinocchio supports mimic joints in RNEA and CRBA but not everywhere).
    """

    def __init__(
        self,
        model: pin.Model,
        *,
        name: str,
        urdf: str,
        spec: URDFSpec,
        floating_base: bool = False,
        source_path: Path | None = None,
        package_dirs: tuple[Path, ...] = (),
        mimic: MimicExpansion | None = None,
    ):
        self.model = model
        self.data = model.createData()
        self.name = name
        self.urdf = urdf
        self.spec = spec
        self.floating_base = floating_base
        self._fixed_base = not floating_base
        self.source_path = source_path
        self.package_dirs = package_dirs
        self.nq: int = model.nq
        self.nv: int = model.nv
        self.joints: list[JointInfo] = self._joint_infos()
        self.joint_names: list[str] = [joint.name for joint in self.joints]
        self._frame_ids = {frame.name: index for index, frame in enumerate(model.frames)}
        self._pool: pin.ModelPool | None = None
        self.mimic = mimic
        self._lower_triangle = np.tri(self.nv, self.nv, -1, dtype=bool)

    def __repr__(self) -> str:
        return f"<Robot {self.name!r}: nq={self.nq}, nv={self.nv}, joints={self.joint_names}>"

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
    def frame_names(self) -> list[str]:
        """Names of every frame: links, joints and fixed frames of the URDF."""
        return list(self._frame_ids)

    @property
    def frame_ids(self) -> dict[str, int]:
        """Pinocchio index of every frame, by name (a copy)."""
        return dict(self._frame_ids)

    @property
    def end_effector(self) -> str:
        """The frame tasks refer to by default: ``end_effector`` if the URDF has that link,
        else the URDF's last link."""
        return "end_effector" if "end_effector" in self.spec.links else list(self.spec.links)[-1]

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

    @property
    def lower_limits(self) -> np.ndarray:
        """Lower position limits per degree of freedom, shape (nv,), in [rad] or [m].

        The six base coordinates of a floating base are unlimited (-inf).
        """
        return np.array([joint.lower for joint in self.joints for _ in range(6 if joint.type == "floating" else 1)])

    @property
    def upper_limits(self) -> np.ndarray:
        """Upper position limits per degree of freedom, shape (nv,), in [rad] or [m]."""
        return np.array([joint.upper for joint in self.joints for _ in range(6 if joint.type == "floating" else 1)])

    def neutral_configuration(self) -> np.ndarray:
        """The neutral configuration (zero joint positions, identity base), shape (nq,)."""
        return pin.neutral(self.model)

    def floating_configuration(self, position, rpy, joints=None) -> np.ndarray:
        """A floating-base configuration from the base pose and the joint positions.

        Args:
            position: Base origin in the world frame, in [m], shape (3,).
            rpy: Base orientation as roll, pitch, yaw in [rad] (rotations about the fixed
                x, y, z axes, as in URDF), shape (3,).
            joints: Joint positions, shape (nv - 6,); default zeros.

        Returns:
            ``q`` of shape (nq,): position, quaternion (x, y, z, w), joints.

        Raises:
            InputError: For a fixed-base robot or wrong sizes.
        """
        if not self.floating_base:
            raise InputError("robot", "a floating-base robot (load it with floating_base=True)", f"fixed-base {self.name!r}")
        position, rpy = as_states({"position": (position, 3), "rpy": (rpy, 3)})[0]
        joints = np.zeros(self.nv - 6) if joints is None else as_states({"joints": (joints, self.nv - 6)})[0][0]
        quaternion = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
        return np.concatenate([position, quaternion, joints])

    def random_configuration(self, rng: np.random.Generator, count: int | None = None) -> np.ndarray:
        """Configurations drawn uniformly within the joint limits.

        Unlimited joints draw from [-π, π]; a floating base draws its position from
        [-1, 1] m and a uniform random orientation.

        Args:
            rng: Random generator (for reproducible draws).
            count: Number of configurations; ``None`` for a single one.

        Returns:
            Shape (nq,) or (count, nq).
        """
        rows = 1 if count is None else count
        lower = np.where(np.isfinite(self.lower_limits), self.lower_limits, -np.pi)
        upper = np.where(np.isfinite(self.upper_limits), self.upper_limits, np.pi)
        if self.floating_base:
            lower, upper = lower[6:], upper[6:]
        joints = rng.uniform(lower, upper, size=(rows, lower.size))
        if self.floating_base:
            quaternion = rng.normal(size=(rows, 4))
            quaternion /= np.linalg.norm(quaternion, axis=1, keepdims=True)
            joints = np.hstack([rng.uniform(-1, 1, size=(rows, 3)), quaternion, joints])
        return joints[0] if count is None else joints

    # ----------------------------------------------------------------------------------
    # Dynamics
    #
    # Each method first tries Pinocchio directly on 1-D float64 arrays: Pinocchio refuses
    # wrong sizes and shapes (caught below), and a NaN or infinity anywhere in the inputs
    # makes the result non-finite, which one dot product detects. Anything else goes
    # through the full boundary check, which names the offending argument.
    # ----------------------------------------------------------------------------------
    def _accept(self, result: np.ndarray, q: np.ndarray) -> bool:
        """Whether a fast-path matrix result can be returned as it is (a NaN or inf makes
        the sum of squares non-finite; a huge finite result is re-checked exactly)."""
        flat = result.ravel()
        return _isfinite(flat.dot(flat)) and (self._fixed_base or self._unit_quaternion(q))

    @staticmethod
    def _unit_quaternion(q: np.ndarray) -> bool:
        quaternion = q[3:7]
        return abs(quaternion.dot(quaternion) - 1.0) < QUATERNION_TOLERANCE

    def _checked(self, **named: np.ndarray) -> tuple[list[np.ndarray], bool]:
        """Full boundary check of state arguments (sizes by name: q has nq, others nv)."""
        arrays, batch = as_states({name: (value, self.nq if name == "q" else self.nv) for name, value in named.items()})
        if self.floating_base:
            norms = np.linalg.norm(arrays[0][..., 3:7], axis=-1)
            if np.any(np.abs(norms - 1.0) >= QUATERNION_TOLERANCE):
                worst = float(np.atleast_1d(norms)[np.argmax(np.abs(np.atleast_1d(norms) - 1.0))])
                raise InputError("q[3:7]", "a unit quaternion (x, y, z, w) for the floating base", f"norm {worst:.9g}")
        return arrays, batch

    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Joint torques ``tau = M(q) a + C(q, v) v + G(q)`` (RNEA).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).

        Returns:
            Torques in [N m] / [N], shape (nv,) or (N, nv).
        """
        try:
            tau = pin.rnea(self.model, self.data, q, v, a)
        except _PINOCCHIO_ERRORS:
            pass
        else:
            if _isfinite(tau.dot(tau)) and (self._fixed_base or self._unit_quaternion(q)):
                return tau
        (q, v, a), batch = self._checked(q=q, v=v, a=a)
        if batch:
            return self._in_parallel(pin.rneaInParallel, q, v, a)
        return self._finite(pin.rnea(self.model, self.data, q, v, a), "tau")

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
        if self.mimic is None:
            try:
                a = pin.aba(self.model, self.data, q, v, tau)
            except _PINOCCHIO_ERRORS:
                pass
            else:
                if _isfinite(a.dot(a)) and (self._fixed_base or self._unit_quaternion(q)):
                    return a
        (q, v, tau), batch = self._checked(q=q, v=v, tau=tau)
        if self.mimic is not None:  # Pinocchio's ABA does not support mimic joints
            if batch:
                result = (
                    np.stack([self._solve_dynamics(*row) for row in zip(q, v, tau, strict=True)])
                    if len(q)
                    else np.zeros((0, self.nv))
                )
            else:
                result = self._solve_dynamics(q, v, tau)
        elif batch:
            result = self._in_parallel(pin.abaInParallel, q, v, tau)
        else:
            result = pin.aba(self.model, self.data, q, v, tau)
        if not np.isfinite(result).all():  # finite inputs: only a singular M gives this
            raise SingularMassMatrixError(self.name, self.massless_joints)
        return result

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
        try:
            mass = self._mass_matrix(q)
            # CRBA works in local frames: a NaN in q need not reach M, so check q too.
            if self._accept(mass, q) and _isfinite(q.dot(q)):
                return mass
        except _PINOCCHIO_ERRORS:
            pass
        (q,), _ = self._checked(q=q)
        return self._finite(self._per_state(self._mass_matrix, q), "M")

    def _mass_matrix(self, q: np.ndarray) -> np.ndarray:
        mass = pin.crba(self.model, self.data, q)  # upper triangle only
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
        try:
            coriolis = self._coriolis(q, v)
        except _PINOCCHIO_ERRORS:
            pass
        else:
            if self._accept(coriolis, q):
                return coriolis
        (q, v), batch = self._checked(q=q, v=v)
        if batch:
            if not len(q):
                return np.zeros((0, self.nv, self.nv))
            return self._finite(np.stack([self._coriolis(qi, vi) for qi, vi in zip(q, v, strict=True)]), "C")
        return self._finite(self._coriolis(q, v), "C")

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
        try:
            torques = pin.computeGeneralizedGravity(self.model, self.data, q)
        except _PINOCCHIO_ERRORS:
            pass
        else:
            if _isfinite(torques.dot(torques)) and (self._fixed_base or self._unit_quaternion(q)):
                return torques
        (q,), batch = self._checked(q=q)
        if batch:
            zeros = np.zeros((q.shape[0], self.nv))
            return self._in_parallel(pin.rneaInParallel, q, zeros, zeros)
        return self._finite(pin.computeGeneralizedGravity(self.model, self.data, q), "G")

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``: the torques at zero acceleration.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).

        Returns:
            Shape (nv,) or (N, nv), in [N m] / [N].
        """
        try:
            torques = pin.nonLinearEffects(self.model, self.data, q, v)
        except _PINOCCHIO_ERRORS:
            pass
        else:
            if _isfinite(torques.dot(torques)) and (self._fixed_base or self._unit_quaternion(q)):
                return torques
        (q, v), batch = self._checked(q=q, v=v)
        if batch:
            return self._in_parallel(pin.rneaInParallel, q, v, np.zeros_like(v))
        return self._finite(pin.nonLinearEffects(self.model, self.data, q, v), "C v + G")

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
        """Kinetic energy ``½ vᵀ M(q) v`` in [J]: a float, or shape (N,) for a batch."""
        (q, v), batch = self._checked(q=q, v=v)
        # From the mass matrix rather than computeKineticEnergy, which refuses mimic joints.
        if batch:
            return np.array([0.5 * vi @ self._mass_matrix(qi) @ vi for qi, vi in zip(q, v, strict=True)])
        return float(0.5 * v @ self._mass_matrix(q) @ v)

    def potential_energy(self, q: np.ndarray) -> float | np.ndarray:
        """Gravitational potential energy ``−Σ m_i gᵀ p_i`` in [J]: a float, or shape (N,).

        Zero when every centre of mass is at height zero (for the default gravity).
        """
        (q,), _ = self._checked(q=q)
        # computePotentialEnergy refuses mimic joints: use the expanded model for those.
        model, data, expand = (
            (self.model, self.data, None) if self.mimic is None else (self.mimic.model, self.mimic.data, self.mimic.q)
        )
        if q.ndim == 2:
            return np.array([pin.computePotentialEnergy(model, data, qi if expand is None else expand(qi)) for qi in q])
        return float(pin.computePotentialEnergy(model, data, q if expand is None else expand(q)))

    # ----------------------------------------------------------------------------------
    # Kinematics
    # ----------------------------------------------------------------------------------
    def frame_id(self, frame: str) -> int:
        """Pinocchio index of a frame (link, joint or fixed frame) by name.

        Raises:
            FrameError: If the robot has no such frame.
        """
        try:
            return self._frame_ids[frame]
        except KeyError:
            raise FrameError(frame, self.name) from None

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Position of a frame's origin in the world frame.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            frame: Link or joint name, e.g. ``"end_effector"``.

        Returns:
            Shape (3,) or (N, 3), in [m].
        """
        frame_id = self.frame_id(frame)
        (q,), _ = self._checked(q=q)
        return self._per_state(lambda qi: self._placement(qi, frame_id).translation.copy(), q)

    def frame_rotation(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Orientation of a frame in the world frame: shape (3, 3) or (N, 3, 3)."""
        frame_id = self.frame_id(frame)
        (q,), _ = self._checked(q=q)
        return self._per_state(lambda qi: self._placement(qi, frame_id).rotation.copy(), q)

    def _placement(self, q: np.ndarray, frame_id: int) -> pin.SE3:
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[frame_id]

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Jacobian of a frame: its velocity is ``J v`` (linear first, then angular).

        Both parts are expressed in world-aligned axes at the frame's origin (Pinocchio's
        ``LOCAL_WORLD_ALIGNED``): rows 0-2 give the origin's velocity in [m/s], rows 3-5
        the angular velocity in [rad/s].

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            frame: Link or joint name.

        Returns:
            Shape (6, nv) or (N, 6, nv).
        """
        frame_id = self.frame_id(frame)
        (q,), _ = self._checked(q=q)
        return self._per_state(
            lambda qi: pin.computeFrameJacobian(self.model, self.data, qi, frame_id, pin.LOCAL_WORLD_ALIGNED).copy(), q
        )

    def frame_bias_acceleration(self, q: np.ndarray, v: np.ndarray, frame: str) -> np.ndarray:
        """``J̇(q, v) v``: the acceleration of a frame's origin at zero joint acceleration.

        The classical (not spatial) acceleration of the origin, in world axes, in [m/s²];
        the frame's acceleration is ``J a + J̇ v`` with ``J`` from :meth:`frame_jacobian`.

        Args:
            q: Configuration, shape (nq,).
            v: Velocity, shape (nv,).
            frame: Link or joint name.

        Returns:
            Shape (3,).
        """
        frame_id = self.frame_id(frame)
        (q, v), _ = self._checked(q=q, v=v)
        pin.forwardKinematics(self.model, self.data, q, v, np.zeros(self.nv))
        return pin.getFrameClassicalAcceleration(self.model, self.data, frame_id, pin.LOCAL_WORLD_ALIGNED).linear.copy()

    def wrench_torques(self, q: np.ndarray, frame: str, wrench: np.ndarray) -> np.ndarray:
        """Joint torques ``J(q)ᵀ w`` that an external wrench on a frame exerts on the joints.

        Args:
            q: Configuration, shape (nq,).
            frame: Link or joint name; the wrench acts at its origin.
            wrench: Force in [N] then torque in [N m], world axes, shape (6,) (or a force
                alone, shape (3,)).

        Returns:
            Shape (nv,): add to the motor torques in forward dynamics, subtract from the
            inverse dynamics' torques.
        """
        wrench = np.asarray(wrench, dtype=float)
        if wrench.shape == (3,):
            wrench = np.concatenate([wrench, np.zeros(3)])
        if wrench.shape != (6,) or not np.isfinite(wrench).all():
            raise InputError("wrench", "6 finite values (force in [N], torque in [N m])", f"shape {wrench.shape}")
        return self.frame_jacobian(q, frame).T @ wrench

    def integrate(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """The configuration reached from ``q`` along the velocity ``dq`` in unit time.

        ``q + dq`` for joints; the floating base's pose moves on SE(3) (Pinocchio's
        ``integrate``), keeping its quaternion unit.
        """
        if self.floating_base:
            return pin.integrate(self.model, q, dq)
        return q + dq

    # ----------------------------------------------------------------------------------
    # Helpers
    # ----------------------------------------------------------------------------------
    @cached_property
    def _threads(self) -> int:
        return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)

    def _model_pool(self) -> pin.ModelPool:
        if self._pool is None:
            self._pool = pin.ModelPool(self.model, self._threads)
        return self._pool

    def _in_parallel(self, algorithm, q: np.ndarray, v: np.ndarray, third: np.ndarray) -> np.ndarray:
        """Run ``rneaInParallel`` or ``abaInParallel`` on stacks of states, shape (N, nv)."""
        if q.shape[0] == 0:
            return np.zeros((0, self.nv))
        # Pinocchio wants one state a column: the transpose of a C-ordered stack, no copy.
        columns = [np.ascontiguousarray(array).T for array in (q, v, third)]
        result = algorithm(self._threads, self._model_pool(), *columns)
        return self._finite(np.asarray(result).reshape(self.nv, q.shape[0]).T.copy(), algorithm.__name__)

    def _finite(self, result: np.ndarray, what: str) -> np.ndarray:
        """Refuse a non-finite result of finite inputs (an overflow), never return it."""
        if not np.isfinite(result).all():
            raise RobodynError(f"robot {self.name!r}: {what} overflowed to a non-finite value for finite inputs.")
        return result

    @staticmethod
    def _per_state(function, q: np.ndarray) -> np.ndarray:
        """Apply a one-state function to a 1-D state or to each row of a 2-D stack."""
        if q.ndim == 1:
            return function(q)
        results = [function(row) for row in q]
        if results:
            return np.stack(results)
        return np.zeros((0, *np.shape(function(np.zeros(q.shape[1])))))
