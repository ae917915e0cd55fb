"""Example: the equations of motion of a zoo robot, one state and a whole trajectory.

Run: ``python scripts/example_dynamics.py [robot]`` (default panda).
"""

import sys

import numpy as np

import robodyn


def main(name: str = "panda") -> None:
    robot = robodyn.load(name)
    print(robot)
    rng = np.random.default_rng(0)
    q = robot.random_configuration(rng)
    v = rng.normal(size=robot.nv)
    a = np.zeros(robot.nv)
    tau = robot.inverse_dynamics(q, v, a)
    print("tau at rest acceleration [N m / N]:", np.round(tau, 3))
    print("M(q) diagonal:", np.round(np.diag(robot.mass_matrix(q)), 4))
    print("G(q):", np.round(robot.gravity(q), 3))
    # 1000 states at once: one state a row.
    qs = robot.random_configuration(rng, 1000)
    torques = robot.inverse_dynamics(qs, np.zeros((1000, robot.nv)), np.zeros((1000, robot.nv)))
    print("largest static torque over 1000 random configurations:", np.round(np.abs(torques).max(axis=0), 2))


if __name__ == "__main__":
    main(*sys.argv[1:])
