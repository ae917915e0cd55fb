"""What a run adds to its figure and recording, as plain data (no matplotlib, no meshcat).

:class:`PlotPanel` is a panel of curves over time (``robodyn.viz.plots.simulation_figure``
draws it beside the joints'); :class:`Polygon` (a closed outline, e.g. the support polygon)
and :class:`MovingPoint` (a point over time, e.g. the centre of mass) are drawn in a
recording (``robodyn.viz.drawings``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class PlotPanel:
    """One panel of a run's figure: curves over time.

    Attributes:
        ylabel: The axis label, with its unit.
        curves: ``(label, t (N,) [s], values (N,), line style)`` each.
    """

    ylabel: str
    curves: tuple[tuple[str, np.ndarray, np.ndarray, str], ...] = field(repr=False)


@dataclass(frozen=True)
class Polygon:
    """A closed outline drawn in a recording (still).

    Attributes:
        name: Its node's name in the scene (letters, digits, ``_``).
        vertices: The corners in order, world frame, shape (K, 3), in [m].
        colour: ``0xRRGGBB``.
    """

    name: str
    vertices: np.ndarray = field(repr=False)
    colour: int = 0x2060E0


@dataclass(frozen=True)
class MovingPoint:
    """A point drawn as a small sphere moving with the recording (linear between samples).

    Attributes:
        name: Its node's name in the scene (letters, digits, ``_``).
        t: Sample times in [s], shape (N,).
        positions: World positions at those times, shape (N, 3), in [m].
        radius: The sphere's radius in [m].
        colour: ``0xRRGGBB``.
    """

    name: str
    t: np.ndarray = field(repr=False)
    positions: np.ndarray = field(repr=False)
    radius: float = 0.012
    colour: int = 0x2060E0

    def at(self, times: np.ndarray) -> np.ndarray:
        """The positions at ``times``, shape (F, 3) (held before the first, after the last sample).

        Args:
            times: In [s], shape (F,).
        """
        return np.column_stack([np.interp(times, self.t, self.positions[:, k]) for k in range(3)])


__all__ = ["MovingPoint", "PlotPanel", "Polygon"]
