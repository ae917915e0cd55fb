"""Sweeps on Dask: the what-if table and the zoo check, one task a variant or a robot.

Each task runs the same function as the local run (:func:`robodyn.sim.whatif.sweep` on one
material × payload × force, :func:`robodyn.verify.zoo_status.zoo_status` on one robot), and
the results come back in the local run's order, so the tables are identical.
"""

from __future__ import annotations

import numpy as np

from robodyn.sim import whatif
from robodyn.verify.zoo_status import ZooStatus, zoo_status


def sweep(
    model: str = "rp_arm",
    *,
    client,
    materials: tuple[str, ...] | None = None,
    payloads: tuple[float, ...] = whatif.DEFAULT_PAYLOADS,
    forces: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),),
    **options,
) -> list[whatif.Variant]:
    """:func:`robodyn.sim.whatif.sweep` with one Dask task a row (same arguments, same rows).

    Args:
        model, materials, payloads, forces, options: As for :func:`robodyn.sim.whatif.sweep`.
        client: A ``dask.distributed.Client``.
    """
    if model == "rp_arm":
        materials = tuple(materials or whatif.DEFAULT_MATERIALS)
        per_material: list[tuple[str, ...] | None] = [(material,) for material in materials]
    else:
        if materials:
            return whatif.sweep(model, materials=materials, payloads=payloads, forces=forces, **options)  # raises
        per_material = [None]
    cells = [(m, (p,), (tuple(np.asarray(f, dtype=float).tolist()),)) for m in per_material for p in payloads for f in forces]
    futures = [client.submit(whatif.sweep, model, materials=m, payloads=p, forces=f, pure=False, **options) for m, p, f in cells]
    return [row for rows in client.gather(futures) for row in rows]


def what_if(model: str = "rp_arm", *, client, materials: tuple[str, ...] | None = None, **options) -> whatif.WhatIfTable:
    """:func:`robodyn.sim.whatif.what_if` with one Dask task a row (same arguments, same table).

    The robot is loaded here once more (the first material's), for the table's names and units.

    Args:
        client: A ``dask.distributed.Client`` (:func:`robodyn.scale.cluster.connect`).
    """
    rows = sweep(model, client=client, materials=materials, **options)
    first = (materials or whatif.DEFAULT_MATERIALS)[:1] if model == "rp_arm" else None
    robot = whatif.model_variants(model, first)[0][1]
    return whatif.table_of(robot, options.get("duration", 1.5), rows)


def zoo_statuses(client, names: list[str]) -> list[ZooStatus]:
    """:func:`robodyn.verify.zoo_status.zoo_statuses` with one Dask task a robot, in ``names`` order.

    Args:
        client: A ``dask.distributed.Client`` (:func:`robodyn.scale.cluster.connect`).
        names: The zoo robots' names.
    """
    return client.gather(client.map(zoo_status, names, pure=False))


__all__ = ["sweep", "what_if", "zoo_statuses"]
