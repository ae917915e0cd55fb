"""Numbers as text for the run summaries (:mod:`robodyn.sim.report`): vectors and numbers
to a given number of significant digits, durations in [ms] or [s].
"""

from __future__ import annotations

from typing import Any

import numpy as np


def vector_text(values: Any, precision: int) -> str:
    """``[v0, v1, ...]`` with ``precision`` significant digits.

    Args:
        values: The numbers, shape (n,).
        precision: Significant digits.
    """
    return "[" + ", ".join(f"{value:.{precision}g}" for value in np.asarray(values, dtype=float)) + "]"


def number_text(value: object, digits: int = 6) -> str:
    """A number with ``digits`` significant digits (``unlimited`` if infinite); anything
    else (a boolean, ``None``, text) as ``str`` gives it.

    Args:
        value: The number (or other value).
        digits: Significant digits.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return "unlimited" if not np.isfinite(value) else f"{value:.{digits}g}"


def seconds_text(value: float) -> str:
    """A duration in [s] as ``12.3 ms`` or ``1.23 s``.

    Args:
        value: The duration in [s].
    """
    return f"{value * 1e3:.3g} ms" if value < 1.0 else f"{value:.3g} s"
