"""Verification: Pinocchio (:mod:`robodyn.dynamics`) against the independent reference (:mod:`robodyn.reference`), for one robot or the whole zoo."""
