"""The C the compiled modules share is written once: the tree LDLᵀ and the thread pool live in core.c."""

from __future__ import annotations

import re
from pathlib import Path

import robodyn.compiled.build as build

FOLDER = Path(build.__file__).parent


def _sources() -> dict[str, str]:
    """Every C file and generator of the compiled engine, by name."""
    return {path.name: path.read_text(encoding="utf-8") for path in sorted([*FOLDER.glob("*.c"), *FOLDER.glob("*.py")])}


def test_one_thread_pool_and_one_factorisation_in_core_c():
    sources = _sources()
    threads = sorted(name for name, text in sources.items() if "pthread_create(" in text)
    assert threads == ["core.c"]
    # A factorisation's pivot division (x = M[k n + i] / d) written anywhere else is a copy.
    pivot = re.compile(r"M\[k \* n \+ i\] / ")
    assert sorted(name for name, text in sources.items() if pivot.search(text)) == ["core.c"]
    assert "RD_LDL_DEFINE(__attribute__((unused)) static, rd_, double)" in sources["runtime.c"]
    assert "RD_LDL_DEFINE(" in sources["simd.py"] and "rd_ldl_factor(" in sources["derivatives.c"]


def test_every_module_source_starts_with_core_c():
    assert build.prelude().endswith(build.CORE.read_text(encoding="utf-8") + "\n")
    assert build.module_source("/* kernels */", "rd_x").startswith(build.prelude())
