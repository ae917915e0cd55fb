"""The dynamics layer: loading a URDF into Pinocchio and the :class:`Robot` that computes τ, M, C, G, forward dynamics, kinematics and energies for one state or a batch."""
