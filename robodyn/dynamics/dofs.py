"""One record per degree of freedom: what every report, plot, file and check says of it.

:class:`Dof` is the one owner of per-degree-of-freedom facts — the coordinate's name, the
joint it belongs to, whether it is linear or angular, its units and its limits — so that
reports, plots, trajectory columns, the regressor's names, ``check`` and ``info`` never work
them out again. :func:`robot_dofs` builds them from the joints of a loaded robot.

Names of a floating base's coordinates (the trajectory format's, docs/trajectory-format.md):
``base.x, base.y, base.z`` (position of the base origin in [m], linear velocity in [m/s]),
``base.qx, base.qy, base.qz, base.qw`` (orientation, a unit quaternion, configuration
only) and ``base.rx, base.ry, base.rz`` (angular velocity in [rad/s], base frame).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace
from typing import Literal

from robodyn.dynamics.joints import JointInfo

#: Names of a floating base's configuration coordinates (position [m], quaternion x, y, z, w).
BASE_Q_NAMES = ("base.x", "base.y", "base.z", "base.qx", "base.qy", "base.qz", "base.qw")
#: Names of a floating base's velocity coordinates (linear [m/s], angular [rad/s], base frame).
BASE_V_NAMES = ("base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz")

Kind = Literal["linear", "angular"]

_UNITS: dict[str, dict[str, str]] = {
    "linear": {"position": "m", "velocity": "m/s", "acceleration": "m/s²", "effort": "N", "effort_word": "force"},
    "angular": {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s²", "effort": "N m", "effort_word": "torque"},
}


@dataclass(frozen=True)
class Dof:
    """One degree of freedom (one entry of ``v``, ``a`` and ``tau``).

    Attributes:
        name: The coordinate's name: the joint's name for a one-degree-of-freedom joint,
            ``base.x`` … ``base.rz`` for a floating base's six (:data:`BASE_V_NAMES`).
        joint: The joint it belongs to (a floating base's six: the root joint's name).
        joint_type: ``"revolute"``, ``"continuous"``, ``"prismatic"`` or ``"floating"``.
        kind: ``"linear"`` (positions in [m], efforts in [N]) or ``"angular"`` ([rad], [N m]).
        index: Its index in ``v``, ``a`` and ``tau`` (0 … nv − 1).
        lower, upper: Position limits in [rad] or [m] (±inf when unlimited).
        velocity_limit: Velocity limit in [rad/s] or [m/s] (inf when not given).
        effort_limit: Effort limit in [N m] or [N] (inf when not given).
        damping: Viscous damping b of the joint, in [N m s/rad] or [N s/m] (0: none).
        friction: Coulomb friction f of the joint, in [N m] or [N] (0: none).
        armature: Rotor inertia reflected to the joint, in [kg m²] or [kg] (0: none).
        actuated: Whether an actuator drives it (a floating base's six: never; a joint of
            a file that lists its actuators, such as MJCF ``<actuator>``: only those
            listed; otherwise every joint). Controllers, ``optimize`` and ``linearize``
            take this set as their default actuated set.
    """

    name: str
    joint: str
    joint_type: str
    kind: Kind
    index: int
    lower: float
    upper: float
    velocity_limit: float
    effort_limit: float
    damping: float = 0.0
    friction: float = 0.0
    armature: float = 0.0
    actuated: bool = True

    @property
    def linear(self) -> bool:
        """Whether positions are lengths in [m] (efforts forces in [N])."""
        return self.kind == "linear"

    @property
    def is_base(self) -> bool:
        """Whether it is one of a floating base's six coordinates."""
        return self.joint_type == "floating"

    @property
    def position_unit(self) -> str:
        """``"m"`` or ``"rad"``."""
        return _UNITS[self.kind]["position"]

    @property
    def velocity_unit(self) -> str:
        """``"m/s"`` or ``"rad/s"``."""
        return _UNITS[self.kind]["velocity"]

    @property
    def acceleration_unit(self) -> str:
        """``"m/s²"`` or ``"rad/s²"``."""
        return _UNITS[self.kind]["acceleration"]

    @property
    def effort_unit(self) -> str:
        """``"N"`` or ``"N m"``."""
        return _UNITS[self.kind]["effort"]

    @property
    def effort_word(self) -> str:
        """``"force"`` or ``"torque"``."""
        return _UNITS[self.kind]["effort_word"]

    def unit(self, quantity: str) -> str:
        """The unit of ``quantity``: ``"q"``/``"position"``, ``"v"``/``"velocity"``,
        ``"a"``/``"acceleration"`` or ``"tau"``/``"effort"``.

        Args:
            quantity: ``"q"``/``"position"``, ``"v"``/``"velocity"``, ``"a"``/``"acceleration"`` or ``"tau"``/``"effort"``.
        """
        aliases = {"q": "position", "v": "velocity", "a": "acceleration", "tau": "effort"}
        return _UNITS[self.kind][aliases.get(quantity, quantity)]


def robot_dofs(
    joints: Sequence[JointInfo],
    *,
    damping: Sequence[float] | None = None,
    friction: Sequence[float] | None = None,
    armature: Sequence[float] | None = None,
    actuated: Collection[str] | None = None,
) -> tuple[Dof, ...]:
    """The degrees of freedom of a robot's joints (``Robot.joints``, root joint first).

    A floating root joint gives six: three linear (``base.x``, ``base.y``, ``base.z``) and
    three angular (``base.rx``, ``base.ry``, ``base.rz``), unlimited.

    Args:
        joints: The joints with coordinates, root joint first.
        damping, friction, armature: Per degree of freedom (length nv; default zeros): the
            model's ``model.damping``, ``model.friction``, ``model.armature``
            (:mod:`robodyn.dynamics.joint_dynamics`).
        actuated: The joints an actuator drives, by name (the file's actuators,
            :attr:`robodyn.urdf.sources.URDFSource.actuated`); ``None``: every joint.
    """
    inf = float("inf")
    dofs: list[Dof] = []
    for joint in joints:
        if joint.type == "floating":
            for axis, name in enumerate(BASE_V_NAMES):
                kind: Kind = "linear" if axis < 3 else "angular"
                dofs.append(Dof(name, joint.name, "floating", kind, len(dofs), -inf, inf, inf, inf, actuated=False))
            continue
        kind = "linear" if joint.type == "prismatic" else "angular"
        driven = actuated is None or joint.name in actuated
        dofs.append(
            Dof(
                joint.name,
                joint.name,
                joint.type,
                kind,
                len(dofs),
                joint.lower,
                joint.upper,
                joint.velocity,
                joint.effort,
                actuated=driven,
            )
        )
    return tuple(_with_dynamics(dof, damping, friction, armature) for dof in dofs)


def _with_dynamics(
    dof: Dof, damping: Sequence[float] | None, friction: Sequence[float] | None, armature: Sequence[float] | None
) -> Dof:
    """``dof`` with its entries of the per-degree-of-freedom arrays given (0 where none is)."""

    def entry(array: Sequence[float] | None) -> float:
        return 0.0 if array is None else float(array[dof.index])

    return replace(dof, damping=entry(damping), friction=entry(friction), armature=entry(armature))


def configuration_names(joints: Sequence[JointInfo]) -> list[str]:
    """A name for each entry of ``q`` (nq of them): :data:`BASE_Q_NAMES` for a floating
    base's seven, then the joints' names.

    Args:
        joints: The joints with coordinates, in order (:func:`robodyn.dynamics.robot.joint_infos`).
    """
    names: list[str] = []
    for joint in joints:
        names.extend(BASE_Q_NAMES if joint.type == "floating" else (joint.name,))
    return names
