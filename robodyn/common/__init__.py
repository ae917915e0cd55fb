"""Shared plumbing below every layer: the numeric input boundary, atomic file output, text escaping and rotations (numpy only, no Pinocchio)."""
