"""Example: the lecture's dynamics-based control: drive the RP arm's end effector to a target.

Run: ``python scripts/example_control.py [output folder]``; writes a plot and an animation.
"""

import sys
from pathlib import Path

import numpy as np

import robodyn
from robodyn.sim.control import TaskSpace
from robodyn.sim.experiment import controller_model
from robodyn.sim.simulation import simulate
from robodyn.viz.plots import plot_simulation
from robodyn.viz.viewer import record


def main(folder: str = "out") -> None:
    robot = robodyn.load("rp_arm")
    target = np.array([0.7, 0.0, 0.7])
    # The controller has its own model of the arm; here it is exact.
    controller = TaskSpace(controller_model(robot), "end_effector", target)
    trajectory = simulate(robot, np.array([0.0, 0.1]), np.zeros(2), 3.0, 1e-3, controller=controller)
    error = np.linalg.norm(robot.frame_position(trajectory.q[-1], "end_effector") - target)
    print(f"end effector {error:.2e} m from the target after 3 s")
    Path(folder).mkdir(exist_ok=True)
    print("plot:", plot_simulation(robot, trajectory, Path(folder) / "control.png", frame="end_effector", target=target))
    print("animation:", record(robot, trajectory, Path(folder) / "control.html"))


if __name__ == "__main__":
    main(*sys.argv[1:])
