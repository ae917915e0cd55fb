"""Equations out: symbolic equations of motion from the independent reference (never Pinocchio), in closed or compact form, rendered as text, LaTeX, PDF, JSON, Python or C; the lecture's equations with their errata."""

from robodyn.equations.derive import Equations, derive_equations
from robodyn.equations.model import operation_count
from robodyn.equations.output import FORMATS, render

__all__ = ["FORMATS", "Equations", "derive_equations", "operation_count", "render"]
