"""The record of a robot file as robodyn reads it: :class:`URDFSource`.

It sits below both the readers that make one (:mod:`robodyn.urdf.sources`,
:mod:`robodyn.urdf.mjcf`) so that neither imports the other for it. This module does not
import Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robodyn.urdf.equality import EqualityRecord


@dataclass(frozen=True)
class URDFSource:
    """A URDF document and where it came from.

    Attributes:
        text: The URDF document.
        name: A short name for the robot (zoo or generated name, file stem, ``"robot"``).
        label: Where it came from, for messages: a path, a robot name or ``"<string>"``.
        path: The file it was read from, if any.
        floating_base: Whether the robot is floating by default (zoo robots that walk or fly).
        package_dirs: Where ``package://`` paths resolve: the zoo's folders, or (files
            and text) the package lookup (:class:`~robodyn.urdf.packages.PackageLookup`,
            a tuple of folders that also knows ``packages=`` and ``$ROS_PACKAGE_PATH``).
        file_format: What the user's file was: ``"urdf"``, ``"xacro"`` (``text`` is its
            expansion) or ``"mjcf"`` (``text`` is the URDF robodyn's MJCF reader wrote).
        equalities: Equality constraints the file declares (MJCF ``<equality>``), as
            records :mod:`robodyn.constraints` turns into the robot's constraints.
        gravity: The gravity the file states, in [m/s²] (MJCF ``<option gravity>``, zero
            under ``<flag gravity="disable"/>``), or ``None``: the robot's gravity unless
            ``gravity=`` is given.
        actuated: The joints the file's actuators drive (MJCF ``<actuator>``), or ``None``
            when the file does not say (every joint is actuated).
        joint_offsets: ``(joint, offset)`` pairs: the file's coordinate is robodyn's plus
            the offset (MJCF ``ref``: MuJoCo's qpos = q + ref), in [rad] or [m].
        ground: The ground plane the file states (MJCF ``<worldbody>``'s plane geom):
            ``(height, normal, friction)``, the height in [m] of the plane along world
            ``z`` at ``x = y = 0``, its unit normal and the Coulomb coefficient; ``None``:
            the file has none (:func:`robodyn.sim.ground.resolve_ground`).
        base_pose: Where the file puts a floating base at the start (MJCF: the free top
            body's ``<body pos quat>``, MuJoCo's ``qpos0``): position in [m] then quaternion
            x, y, z, w, robodyn's ``q[:7]`` (:meth:`robodyn.Robot.default_configuration`);
            ``None``: at the origin, unrotated.
        keyframes: ``(name, qpos)`` of the file's MJCF ``<keyframe>`` s, ``qpos`` in
            MuJoCo's order, completed as MuJoCo completes it; a start only when asked for
            (:meth:`robodyn.Robot.default_configuration` ``keyframe=``).
    """

    text: str
    name: str
    label: str
    path: Path | None = None
    floating_base: bool = False
    package_dirs: tuple[Path, ...] = field(default_factory=tuple)
    file_format: str = "urdf"
    equalities: tuple[EqualityRecord, ...] = ()
    gravity: tuple[float, float, float] | None = None
    actuated: tuple[str, ...] | None = None
    joint_offsets: tuple[tuple[str, float], ...] = ()
    ground: tuple[float, tuple[float, float, float], float] | None = None
    base_pose: tuple[float, ...] | None = None
    keyframes: tuple[tuple[str, tuple[float, ...]], ...] = ()

    @property
    def mesh_context(self) -> dict:
        """Keyword arguments locating mesh files (for :func:`robodyn.urdf.validation.parse_urdf`)."""
        return {"base_dir": self.path.parent if self.path is not None else None, "package_dirs": self.package_dirs}
