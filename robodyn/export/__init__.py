"""robodyn's dynamics where optimisers live: CasADi functions and JAX functions.

- :func:`casadi_functions`: ``casadi.Function`` SX graphs of the compact equations
  (``inverse_dynamics``, ``mass_matrix``, ``nonlinear_effects``, ``gravity``,
  ``forward_dynamics`` by the tree-structured LDLᵀ, frame positions and Jacobians);
- :func:`jax_functions`: the same as pure ``jax.numpy`` functions (jit, vmap, grad);
- :func:`module_source`: either as a standalone module (``robodyn equations MODEL
  --format casadi``/``jax``).

Fixed-base robots (the equations layer models fixed bases); mimic and locked joints,
gravity and kept parameters (``keep_params``) as in :func:`robodyn.derive_equations`.
"""

from robodyn.export.functions import FUNCTIONS, casadi_functions, jax_functions, module_source

__all__ = ["FUNCTIONS", "casadi_functions", "jax_functions", "module_source"]
