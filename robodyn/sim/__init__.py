"""Simulation: integrators, controllers, trajectory files, simulation experiments and the what-if sweep, on top of :class:`robodyn.Robot`."""
