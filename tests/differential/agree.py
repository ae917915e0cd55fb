"""How the harness compares two paths: one assertion that names the case, its seed and the
line that reproduces it."""

from __future__ import annotations

import numpy as np

from tests.differential.cases import Case


class PathsDisagreeError(AssertionError):
    """Two paths that must agree do not."""


def scale(x: np.ndarray) -> float:
    return float(np.max(np.abs(x), initial=0.0))


def agree(
    case: Case,
    what: str,
    actual: object,
    expected: object,
    *,
    rtol: float = 1e-9,
    floor: float = 0.0,
    test: str = "",
) -> None:
    """Assert ``actual`` equals ``expected`` to ``rtol`` relative to the larger of
    ``max |expected|`` and ``floor`` (same shape required).

    Raises:
        PathsDisagreeError: Naming the quantity, the error, the case, its seed and a reproduction.
    """
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    if actual.shape != expected.shape:
        raise PathsDisagreeError(
            f"{what}: shape {actual.shape} != {expected.shape}\n  case {case}\n  repro: {case.reproduction(test)}"
        )
    size = max(scale(expected), floor, 1e-300)
    error = scale(actual - expected) / size if actual.size else 0.0
    if not error <= rtol or not np.all(np.isfinite(actual)):
        where = np.unravel_index(int(np.argmax(np.abs(actual - expected))), actual.shape) if actual.size else ()
        raise PathsDisagreeError(
            f"{what}: relative error {error:.3e} > {rtol:.0e} (worst at index {tuple(map(int, where))}: "
            f"{actual[where] if actual.size else ''} vs {expected[where] if expected.size else ''})\n"
            f"  case {case}\n  repro: {case.reproduction(test)}"
        )


def same(case: Case, what: str, actual: object, expected: object, *, test: str = "") -> None:
    """Assert two non-numeric values (names, orders) are equal, naming the case."""
    if actual != expected:
        raise PathsDisagreeError(f"{what}: {actual!r} != {expected!r}\n  case {case}\n  repro: {case.reproduction(test)}")
