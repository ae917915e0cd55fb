"""The compiled contact step of a robot whose contact modes hold (``contact.c``): one C call
for ``M⁻¹ Jᵀ``, the Delassus matrix, the sticking rows' solve and the complementarity check.

Robot-independent (it takes ``M⁻¹`` and ``J`` as arrays), built once into the compile cache
(:mod:`robodyn.compiled.build`) on the first contact run; without a C compiler, or if the
build or the load fails, :func:`kept_step` is ``None`` and every step takes the Python
path, which solves the same problem (:mod:`robodyn.sim.contact`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path

from robodyn.compiled import build
from robodyn.exceptions import CompileError, CompilerNotFoundError

SOURCE = Path(__file__).with_name("contact.c")


@functools.cache
def kept_step() -> Callable[..., tuple | None] | None:
    """``kept(inverse, joints, centres, offsets, mask, v, tau, bias, guess, axes, settings, q)``
    (``contact.c``), or ``None`` when it cannot be built or loaded here."""
    source = SOURCE.read_text(encoding="utf-8")
    try:
        module = build.keyed_extension(
            "contact-" + build.digest(source), lambda: source, init="rdc_module", label="contact step", prefix="rdc_"
        )
    except (CompileError, CompilerNotFoundError, ImportError, OSError):  # no compiler, or a cache it cannot use
        return None
    step: Callable[..., tuple | None] = module.kept
    return step


__all__ = ["SOURCE", "kept_step"]
