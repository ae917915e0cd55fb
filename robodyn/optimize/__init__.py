"""Optimal motions on robodyn's exported dynamics (CasADi and IPOPT)."""
