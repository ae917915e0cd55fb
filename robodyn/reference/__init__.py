"""The independent Lagrangian reference: robot dynamics from a URDF without Pinocchio."""
