"""A hypothesis strategy for random, physically valid kinematic trees written as URDF."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from robodyn.urdf.edit import rpy_matrix


def urdf_from_seed(seed: int, joints: int, types: list[str]) -> str:
    """A random tree of ``joints`` joints of the given types (cycled), from a seed."""
    rng = np.random.default_rng(seed)
    lines = ['<?xml version="1.0"?>', '<robot name="random">', '  <link name="link0"/>']
    for index in range(1, joints + 1):
        parent = int(rng.integers(0, index))
        joint_type = types[(index - 1) % len(types)] if index > 1 else next(t for t in types if t != "fixed")
        xyz = " ".join(f"{x:.6f}" for x in rng.uniform(-0.4, 0.4, 3))
        rpy = " ".join(f"{x:.6f}" for x in rng.uniform(-np.pi, np.pi, 3))
        axis = rng.normal(size=3) * rng.uniform(0.2, 3.0)  # not unit: the loaders normalise it
        limit = '<limit lower="-1.5" upper="1.5" effort="50" velocity="2"/>' if joint_type in ("revolute", "prismatic") else ""
        lines.append(
            f'  <joint name="j{index}" type="{joint_type}"><parent link="link{parent}"/><child link="link{index}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis[0]:.6f} {axis[1]:.6f} {axis[2]:.6f}"/>{limit}</joint>'
        )
        mass = rng.uniform(0.1, 5.0)
        sides = rng.uniform(0.02, 0.5, 3)
        moments = (
            mass / 12 * np.array([sides[1] ** 2 + sides[2] ** 2, sides[0] ** 2 + sides[2] ** 2, sides[0] ** 2 + sides[1] ** 2])
        )
        rotation = rpy_matrix(rng.uniform(-np.pi, np.pi, 3))
        inertia = rotation @ np.diag(moments) @ rotation.T
        com = " ".join(f"{x:.6f}" for x in rng.uniform(-0.2, 0.2, 3))
        inertia_rpy = " ".join(f"{x:.6f}" for x in rng.uniform(-np.pi, np.pi, 3))
        lines.append(
            f'  <link name="link{index}"><inertial><origin xyz="{com}" rpy="{inertia_rpy}"/><mass value="{mass:.6f}"/>'
            f'<inertia ixx="{inertia[0, 0]:.9f}" ixy="{inertia[0, 1]:.9f}" ixz="{inertia[0, 2]:.9f}" '
            f'iyy="{inertia[1, 1]:.9f}" iyz="{inertia[1, 2]:.9f}" izz="{inertia[2, 2]:.9f}"/></inertial></link>'
        )
    lines.append("</robot>")
    return "\n".join(lines)


JOINT_TYPES = st.lists(st.sampled_from(["revolute", "continuous", "prismatic", "fixed"]), min_size=1, max_size=4).filter(
    lambda types: any(t != "fixed" for t in types)
)

random_urdfs = st.builds(urdf_from_seed, seed=st.integers(0, 2**32 - 1), joints=st.integers(1, 7), types=JOINT_TYPES)
