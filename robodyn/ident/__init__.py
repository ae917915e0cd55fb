"""System identification: base parameters, exciting trajectories, identification from data.

- :func:`base_parameters`: which combinations of the standard inertial parameters motion can
  identify (Gautier's numerical method), their values from the URDF, the map and the base
  regressor; symbolic expressions for small robots.
- :func:`excite`: a periodic Fourier-series trajectory within the joint limits that
  minimises the condition number of the stacked base regressor.
- :func:`identify`: least squares, weighted least squares, or physically consistent
  (semidefinite) identification from measured motion and torques.
- :func:`identified_urdf`: the identified standard parameters written back into the URDF.

The regressor itself is :func:`robodyn.dynamics.regressor.regressor`. This layer sits with
:mod:`robodyn.sim` and :mod:`robodyn.verify` (it imports dynamics, reference, urdf, common).
"""

from __future__ import annotations

from robodyn.ident.base import BaseParameters, base_parameters
from robodyn.ident.excitation import Excitation, excite
from robodyn.ident.identify import Identification, identify
from robodyn.ident.urdf_out import identified_urdf

__all__ = ["BaseParameters", "Excitation", "Identification", "base_parameters", "excite", "identified_urdf", "identify"]
