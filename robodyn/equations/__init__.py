"""Equations out: symbolic equations of motion from the independent reference (never Pinocchio), in closed or compact form, rendered as text, LaTeX, JSON, Python or C; the lecture's equations with their errata."""

from robodyn.equations.derive import Equations, derive_equations, render

__all__ = ["Equations", "derive_equations", "render"]
