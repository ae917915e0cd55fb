"""Measure how the precision of C(q, v), M(q) and tau falls as a robot moves away from the world origin.

ur5 with its base fixed 100 m and 10 km from the world origin (the URDF's world joint
moved), 50 random states: the largest error relative to the largest entry, against the
same robot at the origin. Run: .venv/bin/python scripts/coriolis_far_from_origin.py
"""

from __future__ import annotations

import re

import numpy as np

import robodyn


def main() -> None:
    base = robodyn.load("ur5")
    joint = re.search(r'<joint name="world_joint".*?</joint>', base.urdf, re.S).group(0)
    rng = np.random.default_rng(2)
    q, v, a = base.random_configuration(rng, 50), rng.normal(size=(50, 6)), rng.normal(size=(50, 6))
    at_origin = {"C": base.coriolis_matrix(q, v), "M": base.mass_matrix(q), "tau": base.inverse_dynamics(q, v, a)}
    for offset in (100.0, 1e4):
        moved = robodyn.load(base.urdf.replace(joint, re.sub(r'xyz="[^"]*"', f'xyz="{offset} 0 0"', joint)))
        far = {"C": moved.coriolis_matrix(q, v), "M": moved.mass_matrix(q), "tau": moved.inverse_dynamics(q, v, a)}
        errors = []
        for key, value in at_origin.items():
            axes = tuple(range(1, value.ndim))
            relative = np.abs(far[key] - value).max(axis=axes) / np.abs(value).max(axis=axes)
            errors.append(f"{key} {relative.max():.2g}")
        print(f"{offset:>8g} m: " + ", ".join(errors))


if __name__ == "__main__":
    main()
