"""Optimal motions on robodyn's exported CasADi dynamics, solved by IPOPT.

:func:`point_to_point`: a minimum-effort or minimum-time rest-to-rest motion within the
URDF's position, velocity and effort limits (``robodyn optimize``).
"""

from robodyn.exceptions import OptimizationError
from robodyn.optimize.motion import COSTS, OptimalMotion, point_to_point

__all__ = ["COSTS", "OptimalMotion", "OptimizationError", "point_to_point"]
