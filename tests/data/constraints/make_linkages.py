"""Write the closed-chain robots of tests/constraints (run once; the URDFs are committed).

Each is an open tree whose loop a constraint closes (URDF cannot express a loop); the
constraints are in tests/constraints/linkages.py. Bars along their link's +x, uniform
rods of square section: mass m, centre at L/2, inertia about the centre m L²/12 (and a
small axial one).
"""

from pathlib import Path

HERE = Path(__file__).parent


def bar(name: str, length: float, mass: float, width: float = 0.02) -> str:
    transverse = mass * (length**2 + width**2) / 12
    axial = mass * width**2 / 6
    return f"""  <link name="{name}">
    <inertial>
      <origin xyz="{length / 2} 0 0"/>
      <mass value="{mass}"/>
      <inertia ixx="{axial:.12g}" ixy="0" ixz="0" iyy="{transverse:.12g}" iyz="0" izz="{transverse:.12g}"/>
    </inertial>
  </link>
"""


def joint(name: str, kind: str, parent: str, child: str, xyz: str, axis: str = "0 0 1", rpy: str = "0 0 0") -> str:
    limit = '  <limit lower="-10" upper="10" effort="100" velocity="10"/>\n' if kind != "fixed" else ""
    return f"""  <joint name="{name}" type="{kind}">
    <parent link="{parent}"/>
    <child link="{child}"/>
    <origin xyz="{xyz}" rpy="{rpy}"/>
    <axis xyz="{axis}"/>
  {limit}</joint>
"""


def four_bar(name: str, a: float, b: float, c: float, d: float, masses: tuple[float, float, float], mount_rpy: str = "") -> str:
    """Crank (a) at the origin, coupler (b) on its tip, rocker (c) at (d, 0, 0); axes z."""
    root = "base"
    body = '<robot name="' + name + '">\n  <link name="base"/>\n'
    if mount_rpy:
        body += '  <link name="mount"/>\n' + joint("mount_joint", "fixed", "base", "mount", "0.1 -0.2 0.3", rpy=mount_rpy)
        root = "mount"
    body += bar("crank", a, masses[0]) + bar("coupler", b, masses[1]) + bar("rocker", c, masses[2])
    body += joint("crank_joint", "revolute", root, "crank", "0 0 0")
    body += joint("coupler_joint", "revolute", "crank", "coupler", f"{a} 0 0")
    body += joint("rocker_joint", "revolute", root, "rocker", f"{d} 0 0")
    return body + "</robot>\n"


def slider_crank() -> str:
    """Crank (0.1) and rod (0.4) about z; a slider on an oblique axis (0.8, 0.6, 0) through the origin."""
    body = '<robot name="slider_crank">\n  <link name="base"/>\n'
    body += bar("crank", 0.1, 0.4) + bar("rod", 0.4, 0.6)
    body += """  <link name="slider">
    <inertial>
      <mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/>
    </inertial>
  </link>
"""
    body += joint("crank_joint", "revolute", "base", "crank", "0 0 0")
    body += joint("rod_joint", "revolute", "crank", "rod", "0.1 0 0")
    body += joint("slider_joint", "prismatic", "base", "slider", "0 0 0", axis="0.8 0.6 0")
    return body + "</robot>\n"


if __name__ == "__main__":
    (HERE / "four_bar.urdf").write_text(four_bar("four_bar", 0.1, 0.35, 0.3, 0.4, (0.3, 0.8, 0.6)))
    (HERE / "four_bar_3d.urdf").write_text(four_bar("four_bar_3d", 0.12, 0.33, 0.28, 0.38, (0.25, 0.7, 0.5), "0.4 -0.7 0.3"))
    (HERE / "parallelogram.urdf").write_text(four_bar("parallelogram", 0.3, 0.5, 0.3, 0.5, (0.5, 0.9, 0.5)))
    (HERE / "slider_crank.urdf").write_text(slider_crank())
