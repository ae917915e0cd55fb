"""The compiled-engine tests compare compiled code with Pinocchio: every robot they load is
Pinocchio's (``$ROBODYN_ENGINE=pinocchio``) unless a test asks for ``engine="auto"``
(tests/compiled/test_engine.py), so a robot compiled earlier in the session never answers
for the reference it is compared with."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest


@pytest.fixture(autouse=True)
def pinocchio_reference() -> Iterator[None]:
    previous = os.environ.get("ROBODYN_ENGINE")
    os.environ["ROBODYN_ENGINE"] = "pinocchio"
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop("ROBODYN_ENGINE", None)
        else:
            os.environ["ROBODYN_ENGINE"] = previous
