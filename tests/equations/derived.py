"""Equations derived once a process, for the tests that only read them: the RRP arm's closed
form costs a second of CPU, and several tests read the same one (``derive_equations`` itself,
its options and its refusals, are tested where it is called directly)."""

from __future__ import annotations

import functools

from robodyn.equations import Equations, derive_equations


@functools.cache
def derived(source: str) -> Equations:
    """``derive_equations(source)`` with the default options, derived once a process.

    Args:
        source: A zoo name or a URDF path (as text: the memo's key).
    """
    return derive_equations(source)
