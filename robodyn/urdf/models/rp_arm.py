"""The lecture's revolute–prismatic (RP) arm, generated as URDF from its parameters.

The lecture's revolute–prismatic arm (docs/rp-arm.md), as a rigid-body model:

- ``joint1`` (revolute) turns link 1 in a vertical plane. The lecture's frame is rotated by
  +90° about X so that its Y axis points up (URDF gravity is ``(0, 0, -9.81)``): the joint
  axis is ``(0, -1, 0)``, ``q1 = 0`` points the arm along +X and positive ``q1`` lifts it.
- Link 1 has length ``l1``, mass ``m1``, centre of mass at ``l1/2`` and inertia ``Iz1``
  about the joint axis through its centre of mass.
- ``joint2`` (prismatic) at distance ``l1`` slides link 2 along the arm by ``q2``.
- Link 2 has mass ``m2``, inertia ``Iz2`` and length ``l2``; it is rigid, so its centre of
  mass is at ``r2 = l1 + q2 + c2`` from the shoulder, with ``c2 = l2/2``. (The lecture's
  ``l1 + q2/2`` cannot be a rigid body: see the errata in ``rp-arm.md``.)
- ``end_effector`` is a frame at the far end of link 2, ``l1 + q2 + l2`` from the shoulder.

Both links are drawn as boxes of square cross-section ``width``; a thinner rod behind link 2
shows the slider running inside link 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class RPArmParameters:
    """Parameters of the RP arm. Lengths in [m], masses in [kg], inertias in [kg m²].

    Attributes:
        l1: Length of link 1 (shoulder to the prismatic joint).
        m1: Mass of link 1.
        m2: Mass of link 2.
        l2: Length of link 2; its centre of mass is at ``l2/2`` from the prismatic joint.
        width: Side of the links' square cross-section (drawing, and default inertias).
        Iz1: Inertia of link 1 about the joint axis through its centre of mass; ``None``
            gives a uniform box's ``m1 (l1² + width²) / 12``.
        Iz2: Same for link 2; ``None`` gives ``m2 (l2² + width²) / 12``.
        q1_limits: Range of the revolute joint, in [rad].
        q2_limits: Range of the prismatic joint, in [m].
        effort_limits: Torque limit of joint 1 in [N m], force limit of joint 2 in [N].
        velocity_limits: In [rad/s] and [m/s].
    """

    l1: float = 0.5
    m1: float = 2.0
    m2: float = 1.0
    l2: float = 0.4
    width: float = 0.05
    Iz1: float | None = None
    Iz2: float | None = None
    q1_limits: tuple[float, float] = (-math.pi, math.pi)
    q2_limits: tuple[float, float] = (0.0, 0.3)
    effort_limits: tuple[float, float] = (100.0, 100.0)
    velocity_limits: tuple[float, float] = (3.0, 1.0)

    @classmethod
    def from_material(
        cls, material: str | float, *, l1: float = 0.5, l2: float = 0.4, width: float = 0.05, **limits
    ) -> RPArmParameters:
        """An arm of solid square-section links of one material.

        Args:
            material: ``"abs"`` (plastic), ``"aluminium"``, ``"steel"`` or a density in [kg/m³].
            l1, l2: Link lengths in [m].
            width: Side of the square cross-section in [m].
            **limits: Other fields (joint limits).

        Returns:
            Parameters with masses ``density × length × width²`` and box inertias.
        """
        from robodyn.urdf.materials import box_mass

        return cls(
            l1=l1,
            l2=l2,
            width=width,
            m1=box_mass(material, (l1, width, width)),
            m2=box_mass(material, (l2, width, width)),
            **limits,
        )

    @property
    def inertia1(self) -> float:
        """``Iz1`` in [kg m²], defaulted from the box."""
        return self.Iz1 if self.Iz1 is not None else self.m1 * (self.l1**2 + self.width**2) / 12

    @property
    def inertia2(self) -> float:
        """``Iz2`` in [kg m²], defaulted from the box."""
        return self.Iz2 if self.Iz2 is not None else self.m2 * (self.l2**2 + self.width**2) / 12

    @property
    def c2(self) -> float:
        """Centre of mass of link 2 from the prismatic joint, in [m]."""
        return self.l2 / 2


def _link(name: str, mass: float, length: float, width: float, inertia_axis: float, sleeve: float = 0.0) -> str:
    """A bar along +X from the link origin; ``inertia_axis`` is about the joint (Y) axis.

    ``sleeve`` draws (only draws) a thinner rod reaching that far back from the origin, so
    that the slider visibly stays in link 1 when extended.
    """
    # Inertia about the bar's long axis: that of its square cross-section.
    inertia_long = mass * width**2 / 6
    sleeve_visual = (
        f"""
    <visual>
      <origin xyz="{-sleeve / 2!r} 0 0" rpy="0 0 0"/>
      <geometry><box size="{sleeve!r} {0.6 * width!r} {0.6 * width!r}"/></geometry>
    </visual>"""
        if sleeve > 0
        else ""
    )
    return f"""  <link name="{name}">
    <inertial>
      <origin xyz="{length / 2!r} 0 0" rpy="0 0 0"/>
      <mass value="{mass!r}"/>
      <inertia ixx="{inertia_long!r}" ixy="0" ixz="0" iyy="{inertia_axis!r}" iyz="0" izz="{inertia_axis!r}"/>
    </inertial>
    <visual>
      <origin xyz="{length / 2!r} 0 0" rpy="0 0 0"/>
      <geometry><box size="{length!r} {width!r} {width!r}"/></geometry>
    </visual>{sleeve_visual}
  </link>
"""


def rp_arm_urdf(parameters: RPArmParameters | None = None) -> str:
    """URDF text of the RP arm.

    Args:
        parameters: Arm parameters; ``None`` for the defaults.

    Returns:
        The URDF document, deterministic for given parameters.
    """
    p = parameters or RPArmParameters()
    return f"""<?xml version="1.0"?>
<!-- The revolute-prismatic arm of the lecture, generated by robodyn.urdf.models.rp_arm. -->
<robot name="rp_arm">
  <link name="base_link">
    <visual>
      <origin xyz="0 0 0" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="{p.width!r}" length="{2 * p.width!r}"/></geometry>
    </visual>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/>
    <child link="link1"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 -1 0"/>
    <limit lower="{p.q1_limits[0]!r}" upper="{p.q1_limits[1]!r}" effort="{p.effort_limits[0]!r}" velocity="{p.velocity_limits[0]!r}"/>
  </joint>
{_link("link1", p.m1, p.l1, p.width, p.inertia1)}  <joint name="joint2" type="prismatic">
    <parent link="link1"/>
    <child link="link2"/>
    <origin xyz="{p.l1!r} 0 0" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="{p.q2_limits[0]!r}" upper="{p.q2_limits[1]!r}" effort="{p.effort_limits[1]!r}" velocity="{p.velocity_limits[1]!r}"/>
  </joint>
{_link("link2", p.m2, p.l2, p.width, p.inertia2, sleeve=p.q2_limits[1])}  <joint name="end_effector_joint" type="fixed">
    <parent link="link2"/>
    <child link="end_effector"/>
    <origin xyz="{p.l2!r} 0 0" rpy="0 0 0"/>
  </joint>
  <link name="end_effector"/>
</robot>
"""
