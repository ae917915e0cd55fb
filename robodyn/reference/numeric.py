"""The reference in numbers: the Lagrangian of a kinematic tree, evaluated with numpy.

For every body ``b`` (centre of mass ``p_b(q)``, rotation ``R_b(q)``, mass ``m_b``,
inertia ``I_b`` about its centre of mass in its own frame) and joint ``i`` (world axis
``z_i``, world origin ``o_i``), the geometric Jacobians are

    J_v[b, i] = z_i × (p_b − o_i)   (revolute)    or  z_i  (prismatic)
    J_ω[b, i] = z_i                 (revolute)    or  0

for ``i`` an ancestor of ``b`` (or ``b`` itself), zero otherwise. From the energies
``T = Σ ½ m_b |J_v v|² + ½ (J_ω v)ᵀ R_b I_b R_bᵀ (J_ω v)`` and ``U = −Σ m_b gᵀ p_b``:

    M = Σ_b m_b J_vᵀ J_v + J_ωᵀ R_b I_b R_bᵀ J_ω,     G = ∂U/∂q = −Σ_b m_b J_vᵀ g,
    C_ij = Σ_k Γ_ijk v_k,   Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i),
    τ = M a + C v + G.

``∂M/∂q_k`` is analytic (exact to rounding): moving joint ``k`` rotates everything
beyond it about ``z_k``, so ``∂J[b, i]/∂q_k = z_k × J[b, i]`` when ``k`` is ``i`` or an
ancestor of it and revolute; ``∂J_v[b, i]/∂q_k = z_i × J_v[b, k]`` when ``i`` is a
revolute strict ancestor of ``k``; ``∂(R I Rᵀ)/∂q_k = [z_k]× RIRᵀ − RIRᵀ [z_k]×``.

Every method works on a stack of states at once (one state a row). Mimic joints are
handled in the coordinates of every body, ``theta = S q + offset``: ``M = Sᵀ M_θ S``,
``C = Sᵀ C_θ S``, ``G = Sᵀ G_θ``. No Pinocchio here.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.inputs import as_states
from robodyn.common.rotations import skew
from robodyn.reference import centroidal
from robodyn.reference.mass_derivative import mass_derivative
from robodyn.reference.tree import KinematicTree
from robodyn.urdf.validation import URDFSpec

#: Largest number of states processed at once.
CHUNK = 256
#: Bound on the entries of the largest intermediate array (the derivative of the body
#: Jacobians: bodies × joints² × 3 a state), which sets the chunk for large robots.
MAX_CHUNK_ENTRIES = 4_000_000


def _quaternion_matrix(quaternion: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions (x, y, z, w), shape (N, 4) -> (N, 3, 3)."""
    x, y, z, w = (quaternion / np.linalg.norm(quaternion, axis=1, keepdims=True)).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def _base_bias(v: np.ndarray) -> np.ndarray:
    """``θ̈ − a`` for a floating base: the virtual coordinates' accelerations minus
    Pinocchio's (body-frame) ones, at the virtual joints' zero.

    With the base pose ``(p0 + R0 ξ_lin, R0 Rx(ξ4) Ry(ξ5) Rz(ξ6))`` the body-frame velocity
    ``(v_lin, ω)`` equals ``ξ̇`` at ``ξ = 0``, and differentiating once more gives
    ``a_lin = ξ̈_lin − ω × v_lin`` and ``a_ang = ξ̈_ang + (ω_y ω_z, −ω_x ω_z, ω_x ω_y)``.
    """
    linear, angular = v[:, :3], v[:, 3:6]
    bias = np.zeros_like(v)
    bias[:, :3] = np.cross(angular, linear)
    bias[:, 3:6] = -np.stack([angular[:, 1] * angular[:, 2], -angular[:, 0] * angular[:, 2], angular[:, 0] * angular[:, 1]], -1)
    return bias


class ReferenceRobot:
    """The independent Lagrangian model of a robot (same method names as ``Robot``).

    Build one with :func:`robodyn.reference.load`.

    Attributes:
        name: Robot name.
        urdf: The URDF text it was built from.
        spec: The validated URDF.
        tree: The kinematic tree (bodies in topological order).
        joint_names: Joints in the order of ``q`` (the URDF's depth-first order, which may
            differ from Pinocchio's: compare by name).
        nq, nv: Number of coordinates. A floating base adds Pinocchio's base pose to ``q``
            (position, quaternion x, y, z, w: ``nq = nv + 1``) and its body-frame velocity
            (linear, angular) to ``v``; the reference models it by six virtual joints
            evaluated at zero, hanging from that pose, and maps its accelerations
            (:func:`_base_bias`) so that ``tau``, ``M``, ``C v`` and ``G`` are Pinocchio's.
        gravity_vector: Gravity in the world frame, in [m/s²].
    """

    def __init__(self, tree: KinematicTree, *, name: str, urdf: str, spec: URDFSpec, gravity: np.ndarray):
        self.tree = tree
        self.name = name
        self.urdf = urdf
        self.spec = spec
        self.floating_base = tree.floating_base
        self.joint_names = ["root_joint", *tree.joint_names[6:]] if self.floating_base else list(tree.joint_names)
        self.nv = len(tree.joint_names)
        self.nq = self.nv + 1 if self.floating_base else self.nv
        self.gravity_vector = np.asarray(gravity, float)
        bodies = tree.bodies
        self._origins = np.array([body.origin for body in bodies]).reshape(-1, 4, 4)
        self._axes = np.array([body.axis for body in bodies]).reshape(-1, 3)
        self._revolute = np.array([body.revolute for body in bodies], dtype=bool)
        self._masses = np.array([body.mass for body in bodies])
        self._coms = np.array([body.com for body in bodies]).reshape(-1, 3)
        self._inertias = np.array([body.inertia for body in bodies]).reshape(-1, 3, 3)
        self._axis_skews = skew(self._axes)
        self._selection = tree.selection
        self._offset = tree.offset

    def __repr__(self) -> str:
        return f"<ReferenceRobot {self.name!r}: n={self.nv}, joints={self.joint_names}>"

    # ----------------------------------------------------------------------------------
    # Kinematics of every body, for a stack of body coordinates theta (N, n_bodies)
    # ----------------------------------------------------------------------------------
    def _kinematics(self, theta: np.ndarray, base: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, ...]:
        """World rotations R (N, B, 3, 3) and origins (N, B, 3) of the body frames, joint
        axes z and origins o (N, B, 3). ``base``: per-state rotation (N, 3, 3) and position
        (N, 3) of the frame the root bodies hang from (a floating base's pose)."""
        count, bodies = theta.shape
        rotations = np.empty((count, bodies, 3, 3))
        positions = np.empty((count, bodies, 3))
        axes = np.empty((count, bodies, 3))
        joint_origins = np.empty((count, bodies, 3))
        identity = np.eye(3)
        for index, body in enumerate(self.tree.bodies):
            if body.parent < 0:
                parent_rotation, parent_position = (identity[None], np.zeros((1, 3))) if base is None else base
            else:
                parent_rotation, parent_position = rotations[:, body.parent], positions[:, body.parent]
            joint_rotation = parent_rotation @ self._origins[index, :3, :3]
            joint_origins[:, index] = parent_position + parent_rotation @ self._origins[index, :3, 3]
            axes[:, index] = joint_rotation @ self._axes[index]
            angle = theta[:, index]
            if body.revolute:
                skew = self._axis_skews[index]
                rodrigues = identity + np.sin(angle)[:, None, None] * skew + (1 - np.cos(angle))[:, None, None] * (skew @ skew)
                rotations[:, index] = joint_rotation @ rodrigues
                positions[:, index] = joint_origins[:, index]
            else:
                rotations[:, index] = joint_rotation
                positions[:, index] = joint_origins[:, index] + axes[:, index] * angle[:, None]
        return rotations, positions, axes, joint_origins

    def _jacobians(
        self, points: np.ndarray, axes: np.ndarray, joint_origins: np.ndarray, rows: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Linear and angular Jacobians of points carried by bodies: (N, P, B, 3) each.

        Args:
            points: World points, (N, P, 3).
            axes, joint_origins: From :meth:`_kinematics`.
            rows: Boolean (P, B): which joints move each point.
        """
        lever = points[:, :, None, :] - joint_origins[:, None, :, :]
        joint_axes = np.broadcast_to(axes[:, None, :, :], lever.shape)
        revolute = self._revolute[None, None, :, None]
        moves = rows[None, :, :, None]
        linear = np.where(revolute, np.cross(joint_axes, lever), joint_axes) * moves
        angular = np.where(revolute, joint_axes, 0.0) * moves
        return linear, angular

    # ----------------------------------------------------------------------------------
    # The Lagrangian terms in body coordinates
    # ----------------------------------------------------------------------------------
    def _bodies(self, q: np.ndarray) -> tuple[np.ndarray, ...]:
        """Each body at stacked configurations (N, nq): centres of mass (N, B, 3) [m], their
        linear and angular Jacobians (N, B, 3, n), inertias about them in world axes
        (N, B, 3, 3) [kg m²] and the joint axes (the kinematics' own)."""
        base = None
        if self.floating_base:  # the virtual joints sit at zero, hanging from the base pose
            base = (_quaternion_matrix(q[:, 3:7]), q[:, :3])
            q = np.hstack([np.zeros((len(q), 6)), q[:, 7:]])
        theta = q @ self._selection.T + self._offset
        rotations, positions, axes, joint_origins = self._kinematics(theta, base)
        coms = positions + np.einsum("nbij,bj->nbi", rotations, self._coms)
        linear, angular = self._jacobians(coms, axes, joint_origins, self.tree.ancestors)
        world_inertia = rotations @ self._inertias[None] @ np.swapaxes(rotations, -1, -2)
        return coms, linear, angular, world_inertia, axes

    def _terms(self, q: np.ndarray, derivative: bool) -> dict[str, np.ndarray]:
        coms, linear, angular, world_inertia, axes = self._bodies(q)
        weighted = self._masses[None, :, None, None] * linear
        mass = np.einsum("nbia,nbja->nij", weighted, linear, optimize=True) + np.einsum(
            "nbia,nbac,nbjc->nij", angular, world_inertia, angular, optimize=True
        )
        terms = {
            "M": mass,
            "G": -np.einsum("nbia,a->ni", weighted, self.gravity_vector),
            "U": -np.einsum("b,nba,a->n", self._masses, coms, self.gravity_vector),
        }
        if derivative:
            terms["dM"] = mass_derivative(
                linear, angular, weighted, world_inertia, axes, ancestors=self.tree.ancestors, revolute=self._revolute
            )
        return terms

    def _evaluate(self, q: np.ndarray, v: np.ndarray | None, a: np.ndarray | None) -> dict[str, np.ndarray]:
        """All terms in the independent coordinates, for stacks q, v, a (chunked)."""
        results: dict[str, list[np.ndarray]] = {}
        selection = self._selection
        bodies = len(self.tree.bodies)
        size = max(1, min(CHUNK, MAX_CHUNK_ENTRIES // (3 * bodies**3 + 1)))
        for start in range(0, max(len(q), 1), size):
            chunk = slice(start, start + size)
            terms = self._terms(q[chunk], derivative=v is not None)
            out = {
                "M": selection.T @ terms["M"] @ selection,
                "G": terms["G"] @ selection,
                "U": terms["U"],
            }
            if v is not None:
                theta_dot = v[chunk] @ selection.T
                dM = terms["dM"]
                # Γ_ijk = ½ (∂M_ij/∂θ_k + ∂M_ik/∂θ_j − ∂M_jk/∂θ_i)
                christoffel = 0.5 * (dM + np.einsum("nikj->nijk", dM) - np.einsum("njki->nijk", dM))
                coriolis_theta = np.einsum("nijk,nk->nij", christoffel, theta_dot)
                out["C"] = selection.T @ coriolis_theta @ selection
                out["Mdot"] = selection.T @ np.einsum("nijk,nk->nij", dM, theta_dot) @ selection
                out["Cv"] = np.einsum("nij,nj->ni", out["C"], v[chunk])
                if self.floating_base:
                    out["Cv"] = out["Cv"] + np.einsum("nij,nj->ni", out["M"], _base_bias(v[chunk]))
                if a is not None:
                    out["tau"] = np.einsum("nij,nj->ni", out["M"], a[chunk]) + out["Cv"] + out["G"]
            for key, value in out.items():
                results.setdefault(key, []).append(value)
        return {key: np.concatenate(values)[: len(q)] for key, values in results.items()}

    def _call(self, key: str, **named: np.ndarray) -> np.ndarray:
        if self.floating_base and key in ("C", "Mdot"):
            raise NotImplementedError(
                "with a floating base the reference compares tau, M, C v and G (its C is in other coordinates)"
            )
        arrays, batch = as_states({name: (value, self.nq if name == "q" else self.nv) for name, value in named.items()})
        stacked = [array if batch else array[None] for array in arrays]
        q, v, a = [*stacked, None, None][:3]
        assert q is not None  # every quantity takes q first
        result = self._evaluate(q, v, a)[key]
        return result if batch else result[0]

    # ----------------------------------------------------------------------------------
    # Public API, mirroring robodyn.Robot
    # ----------------------------------------------------------------------------------
    def terms(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> dict[str, np.ndarray]:
        """Every term at once, for stacks of states (one a row): ``tau``, ``M``, ``Cv``, ``G``
        and, on a fixed base, ``C`` and ``Mdot`` (shapes as their methods give for a stack),
        in one pass: ``∂M/∂q`` is computed once, not once a method.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        (q, v, a), _ = as_states({"q": (q, self.nq), "v": (v, self.nv), "a": (a, self.nv)})
        values = self._evaluate(np.atleast_2d(q), np.atleast_2d(v), np.atleast_2d(a))
        names = ("tau", "M", "Cv", "G") if self.floating_base else ("tau", "M", "Cv", "G", "C", "Mdot")
        return {name: values[name] for name in names}

    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``tau = M a + C v + G``, shape (n,) or (N, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
            a: Acceleration, shape (nv,) or (N, nv), in [rad/s²] / [m/s²].
        """
        return self._call("tau", q=q, v=v, a=a)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``M(q)``, shape (n, n) or (N, n, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
        """
        return self._call("M", q=q)

    def mass_matrix_derivative(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``dM/dt = Σ_k ∂M/∂q_k v_k`` (analytic), shape (n, n) or (N, n, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        return self._call("Mdot", q=q, v=v)

    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v)`` from the Christoffel symbols of ``M``, shape (n, n) or (N, n, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        return self._call("C", q=q, v=v)

    def coriolis_forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v``, shape (n,) or (N, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        return self._call("Cv", q=q, v=v)

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """``G(q) = ∂U/∂q``, shape (n,) or (N, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
        """
        return self._call("G", q=q)

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``, shape (n,) or (N, n).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        return self._call("Cv", q=q, v=v) + self.gravity(q)

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``a = M⁻¹ (tau − C v − G)``, shape (nv,) or (N, nv); ``q`` has nq entries a state.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
            tau: Torques, shape (nv,) or (N, nv), in [N m] / [N].
        """
        (q, v, tau), _ = as_states({"q": (q, self.nq), "v": (v, self.nv), "tau": (tau, self.nv)})
        return np.linalg.solve(self.mass_matrix(q), (tau - self.nonlinear_effects(q, v))[..., None])[..., 0]

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float | np.ndarray:
        """``T = ½ vᵀ M v`` in [J]: a float or shape (N,); ``q`` has nq entries a state.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        (q, v), batch = as_states({"q": (q, self.nq), "v": (v, self.nv)})
        energy = 0.5 * np.einsum("...i,...ij,...j->...", v, self.mass_matrix(q), v)
        return energy if batch else float(energy)

    def potential_energy(self, q: np.ndarray) -> float | np.ndarray:
        """``U = −Σ m_b gᵀ p_b`` in [J]: a float or shape (N,).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
        """
        energy = self._call("U", q=q)
        return energy if np.ndim(energy) else float(energy)

    # ----------------------------------------------------------------------------------
    # Centroidal quantities (robodyn.reference.centroidal), body by body
    # ----------------------------------------------------------------------------------
    def body_motion(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        """The robot's bodies (armature rotors left out) at stacked states: masses (B,),
        centres of mass (N, B, 3) [m], their velocities (N, B, 3) [m/s], inertias about
        them in world axes (N, B, 3, 3) [kg m²], angular velocities (N, B, 3) [rad/s].

        Args:
            q: Configurations, shape (N, nq), in [rad] / [m].
            v: Velocities, shape (N, nv), in [rad/s] / [m/s].
        """
        coms, linear, angular, inertias, _ = self._bodies(q)
        rate = v @ self._selection.T  # θ̇: a floating base's virtual rates are its body-frame twist
        keep = np.array([not body.rotor for body in self.tree.bodies])
        velocities = np.einsum("nbia,ni->nba", linear, rate)
        omegas = np.einsum("nbia,ni->nba", angular, rate)
        return self._masses[keep], coms[:, keep], velocities[:, keep], inertias[:, keep], omegas[:, keep]

    def center_of_mass(self, q: np.ndarray) -> np.ndarray:
        """``Σ mᵢ pᵢ / m`` in [m], world axes, shape (3,) or (N, 3).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
        """
        (q,), batch = as_states({"q": (q, self.nq)})
        stacked = q if batch else q[None]
        masses, coms, *_ = self.body_motion(stacked, np.zeros((len(stacked), self.nv)))
        result = centroidal.center_of_mass(masses, coms)
        return result if batch else result[0]

    def centroidal_momentum(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``(Σ mᵢ vᵢ, Σ (pᵢ − c) × mᵢ vᵢ + Iᵢ ωᵢ)``: linear [kg m/s] then angular
        [kg m²/s] momentum about the centre of mass, world axes, shape (6,) or (N, 6).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in the reference's joint order (:attr:`joint_names`), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s] (a floating base: its body-frame twist first).
        """
        (q, v), batch = as_states({"q": (q, self.nq), "v": (v, self.nv)})
        stacked = [q, v] if batch else [q[None], v[None]]
        result = centroidal.centroidal_momentum(*self.body_motion(*stacked))
        return result if batch else result[0]
