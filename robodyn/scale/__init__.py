"""Beyond one machine: trajectory datasets in chunks, robot dynamics on Dask arrays.

- :mod:`robodyn.scale.datasets`: files larger than memory (CSV, NPZ, Parquet) read and
  written a chunk of rows at a time;
- :mod:`robodyn.scale.torques`: inverse dynamics (and G, M) over a whole file, locally or
  on a ``dask.distributed`` cluster (``robodyn torques``);
- :mod:`robodyn.scale.arrays`: ``inverse_dynamics``, ``forward_dynamics``, ``gravity``,
  ``mass_matrix`` accepting Dask arrays;
- :mod:`robodyn.scale.cluster`: ``--scheduler ADDRESS|local:N``;
- :mod:`robodyn.scale.sweeps`: the what-if table and the zoo check, one Dask task a row;
- :mod:`robodyn.scale.csvio`: CSV rows through pyarrow when installed, numpy otherwise.

Dask and pyarrow are optional (the ``robodyn[scale]`` extra: ``pip install '.[scale]'`` in a clone); CSV and NPZ need neither.
Layer: above :mod:`robodyn.sim`, below :mod:`robodyn.viz`.
"""

from robodyn.scale.arrays import forward_dynamics, gravity, inverse_dynamics, mass_matrix

__all__ = ["forward_dynamics", "gravity", "inverse_dynamics", "mass_matrix"]
