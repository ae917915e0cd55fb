"""The ``robodyn`` command: parses arguments, calls the library, prints reports. No computation of its own."""

from robodyn.cli.app import main

__all__ = ["main"]
