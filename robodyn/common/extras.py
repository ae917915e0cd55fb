"""Optional dependencies: import them by name, or refuse in one line naming the extra to install.

``pip install .`` in a clone of robodyn brings loading, dynamics, the reference and the
equations. The rest
comes with extras: ``robodyn[zoo]`` (example-robot-data's robots), ``robodyn[viewer]``
(meshcat recordings and the live viewer), ``robodyn[plots]`` (matplotlib figures), and
``robodyn[all]`` for everything.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from robodyn.exceptions import MissingExtraError


def require(module: str, *, extra: str, purpose: str) -> ModuleType:
    """Import an optional module, or raise :class:`MissingExtraError` naming the extra.

    Args:
        module: Module to import, e.g. ``"meshcat"``.
        extra: The robodyn extra that installs it, e.g. ``"viewer"``.
        purpose: What it is needed for, e.g. ``"recordings"``.
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(module, extra, purpose) from None
