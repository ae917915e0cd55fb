"""Robot dynamics on Dask arrays: one state a row, computed a chunk of rows at a time.

Each function takes numpy arrays (computed here, as :class:`robodyn.Robot` would) or Dask
arrays (a lazy Dask array back, of one ``map_blocks`` over row chunks). The robot travels
to the workers by its source and options and is rebuilt there once per process
(:mod:`robodyn.dynamics.pickling`). A chunk whose states the robot refuses raises a
:class:`~robodyn.exceptions.TrajectoryError` naming the rows (1-based) and the reason.
"""

from __future__ import annotations

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, RobodynError, TrajectoryError


def _is_dask(*arrays) -> bool:
    return any(type(array).__module__.startswith("dask") for array in arrays)


def _block(*blocks: np.ndarray, robot: Robot, method: str, block_info=None) -> np.ndarray:
    """``robot.<method>`` on one chunk of rows; a refusal names the rows of the whole array."""
    first = block_info[0]["array-location"][0][0] + 1 if block_info else 1
    try:
        return getattr(robot, method)(*blocks)
    except RobodynError as error:
        for offset in range(len(blocks[0])):
            try:
                getattr(robot, method)(*(block[offset] for block in blocks))
            except RobodynError as row_error:
                raise TrajectoryError("dask array", str(row_error).rstrip("."), (first + offset, first + offset)) from None
        raise TrajectoryError("dask array", str(error).rstrip("."), (first, first + len(blocks[0]) - 1)) from None


def _map(robot: Robot, method: str, named: dict, out: tuple[int, ...]):
    """``map_blocks`` of ``robot.<method>`` over the row chunks of the first argument."""
    import dask.array as da

    arrays = []
    for name, value in named.items():
        array = da.asarray(value)
        width = robot.nq if name == "q" else robot.nv
        if array.ndim != 2 or array.shape[1] != width:
            raise InputError(name, f"a 2-D array of {width} columns (one state a row)", f"shape {array.shape}")
        arrays.append(array)
    rows = arrays[0].chunks[0]
    if any(array.shape[0] != arrays[0].shape[0] for array in arrays):
        raise InputError(", ".join(named), "arrays of the same number of rows", str([a.shape[0] for a in arrays]))
    arrays = [array.rechunk((rows, -1)) for array in arrays]
    chunks = (rows, *((size,) for size in out))
    new_axis = list(range(2, 1 + len(out))) or None
    return da.map_blocks(_block, *arrays, robot=robot, method=method, dtype=float, chunks=chunks, new_axis=new_axis)


def inverse_dynamics(robot: Robot, q, v, a):
    """Torques ``tau = M(q) a + C(q, v) v + G(q)``, shape (N, nv), in [N m] / [N].

    Args:
        robot: The robot.
        q: Configurations, shape (N, nq) (numpy or Dask; rows chunked as wanted).
        v: Velocities, shape (N, nv).
        a: Accelerations, shape (N, nv).
    """
    if not _is_dask(q, v, a):
        return robot.inverse_dynamics(q, v, a)
    return _map(robot, "inverse_dynamics", {"q": q, "v": v, "a": a}, (robot.nv,))


def forward_dynamics(robot: Robot, q, v, tau):
    """Accelerations ``M(q)⁻¹ (tau − C(q, v) v − G(q))``, shape (N, nv).

    Args:
        robot: The robot.
        q: Configurations, shape (N, nq) (numpy or Dask).
        v: Velocities, shape (N, nv).
        tau: Joint torques and forces, shape (N, nv), in [N m] / [N].
    """
    if not _is_dask(q, v, tau):
        return robot.forward_dynamics(q, v, tau)
    return _map(robot, "forward_dynamics", {"q": q, "v": v, "tau": tau}, (robot.nv,))


def gravity(robot: Robot, q):
    """Generalised gravity ``G(q)``, shape (N, nv), in [N m] / [N].

    Args:
        robot: The robot.
        q: Configurations, shape (N, nq) (numpy or Dask).
    """
    if not _is_dask(q):
        return robot.gravity(q)
    return _map(robot, "gravity", {"q": q}, (robot.nv,))


def mass_matrix(robot: Robot, q):
    """Mass matrices ``M(q)``, shape (N, nv, nv), in [kg m²] / [kg].

    Args:
        robot: The robot.
        q: Configurations, shape (N, nq) (numpy or Dask).
    """
    if not _is_dask(q):
        return robot.mass_matrix(q)
    return _map(robot, "mass_matrix", {"q": q}, (robot.nv, robot.nv))


__all__ = ["forward_dynamics", "gravity", "inverse_dynamics", "mass_matrix"]
