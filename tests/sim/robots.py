"""A small robot for unit tests: a body with mass, a revolute and a prismatic joint."""

#: URDF text: ``body`` (2 kg) -- ``shoulder`` (revolute about y) -- ``slide`` (prismatic along x).
SLIDER_URDF = """<?xml version="1.0"?>
<robot name="slider">
  <link name="body">
    <inertial><origin xyz="0 0 0"/><mass value="2.0"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.1 0 0"/><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="tip">
    <inertial><origin xyz="0 0 0"/><mass value="0.5"/><inertia ixx="0.005" iyy="0.005" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="body"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="50" velocity="3"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="arm"/><child link="tip"/><origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="20" velocity="1"/>
  </joint>
</robot>
"""
