"""Checks at the numeric boundary: every state vector robodyn receives passes through here.

One shape rule everywhere: a 1-D array is one state and gives one result; a 2-D array holds
one state a row and gives a stacked result, whatever the number of rows. This module does
not import Pinocchio.
"""

from __future__ import annotations

import warnings

import numpy as np

from robodyn.common.text import counted, printable
from robodyn.exceptions import InputError


def as_state(value: object, name: str, size: int) -> np.ndarray:
    """Convert one state vector or a stack of them to float64 and check it.

    Args:
        value: Array-like of shape ``(size,)`` or ``(N, size)``.
        name: Argument name, for the error message (``"q"``, ``"v"``, ...).
        size: Expected length of one state.

    Returns:
        A float64 array of the same shape (no copy when already float64).

    Raises:
        InputError: If the value is not real numbers (complex, strings, booleans are
            refused), has the wrong shape or length, or holds a NaN or an infinity.
    """
    array = _real_array(value, name, size)
    if array.ndim == 1:
        if array.shape[0] != size:
            raise InputError(name, counted(size, "value"), counted(array.shape[0], "value"))
    elif array.ndim == 2:
        if array.shape[1] != size:
            raise InputError(name, f"{counted(size, 'value')} a row", f"{counted(array.shape[1], 'value')} a row")
    else:
        raise InputError(
            name, f"a 1-D array of {size} values or a 2-D array with one state a row", f"{array.ndim}-D shape {array.shape}"
        )
    if not np.isfinite(array).all():
        bad = np.argwhere(~np.isfinite(array))[0]
        raise InputError(
            name, "finite", f"{array[tuple(bad)]} at index {tuple(int(i) for i in bad) if array.ndim > 1 else int(bad[0])}"
        )
    return array


def _real_array(value: object, name: str, size: int) -> np.ndarray:
    """``value`` as float64 without any silent conversion: real numbers only.

    Complex numbers (even with a zero imaginary part), strings, booleans, ``None`` and
    ragged nestings are refused; no numpy warning is printed on the way.
    """
    expected = f"an array of {size} real numbers"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a ComplexWarning, an overflow...: refuse, never print
        try:
            raw = np.asarray(value)
            if raw.dtype.kind == "O":  # e.g. Fractions, Decimals, or a mix
                if any(isinstance(item, (complex, np.complexfloating, str, bytes, bool, np.bool_)) for item in raw.flat):
                    raise TypeError
                raw = raw.astype(np.float64)
            if raw.dtype.kind not in "iuf":
                raise TypeError
            return raw.astype(np.float64, copy=False)
        except (TypeError, ValueError, OverflowError, Warning):
            received = f"{raw.dtype} values" if "raw" in locals() and raw.dtype.kind == "c" else type(value).__name__
            raise InputError(name, expected, f"{received} {printable(repr(value))[:60]}") from None


def as_states(named: dict[str, tuple[object, int]]) -> tuple[list[np.ndarray], bool]:
    """Check several arguments that must share one shape rule (all 1-D or all N rows).

    Args:
        named: ``{name: (value, size)}`` in argument order.

    Returns:
        The checked arrays, and whether they are batches (2-D).

    Raises:
        InputError: If any argument is invalid, or they mix 1-D and 2-D or row counts.
    """
    arrays = [as_state(value, name, size) for name, (value, size) in named.items()]
    first_name, first = next(iter(named)), arrays[0]
    for name, array in zip(named, arrays, strict=True):
        if array.shape[:-1] != first.shape[:-1]:
            expected = "1-D like " + first_name if first.ndim == 1 else f"{first.shape[0]} rows like {first_name}"
            received = "a 1-D array" if array.ndim == 1 else f"{array.shape[0]} rows"
            raise InputError(name, expected, received)
    return arrays, first.ndim == 2
