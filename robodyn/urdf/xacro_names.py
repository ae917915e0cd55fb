"""The names a xacro expression sees besides the file's own: the ``math`` functions and
constants xacro documents, and a few bounded builtins.

``math``: the real functions (:data:`MATH_FUNCTIONS`; not ``factorial``, ``comb``, ``perm``,
``prod``, whose results grow without bound) and :data:`MATH_CONSTANTS`, bare (``pi``,
``sin(x)``) and as ``math.pi``. Builtins: xacro's documented ``list dict map len str float
int bool min max round`` (and ``sorted``, ``range``, ``abs``), each bounded to
:data:`~robodyn.urdf.xacro_eval.MAX_SIZE` and never given a function but in ``map``. Not
``python.*`` (``vars``, ``type``, ``getattr``-like reach into objects). This module does
not import Pinocchio or the xacro package.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from robodyn.urdf.xacro_eval import MAX_SIZE, ExpressionError, Function, Namespace, size

#: The ``math`` names xacro documents: the real functions and the constants.
MATH_FUNCTIONS = tuple(
    [
        "acos",
        "acosh",
        "asin",
        "asinh",
        "atan",
        "atan2",
        "atanh",
        "ceil",
        "copysign",
        "cos",
        "cosh",
        "degrees",
        "dist",
        "erf",
        "erfc",
        "exp",
        "expm1",
        "fabs",
        "floor",
        "fmod",
        "gamma",
        "hypot",
        "isclose",
        "isfinite",
        "isinf",
        "isnan",
        "ldexp",
        "lgamma",
        "log",
        "log10",
        "log1p",
        "log2",
        "pow",
        "radians",
        "remainder",
        "sin",
        "sinh",
        "sqrt",
        "tan",
        "tanh",
        "trunc",
    ]
)
MATH_CONSTANTS = ("pi", "e", "tau", "inf", "nan")


def _bounded_list(items: Iterable[Any]) -> list:
    result: list = []
    total = 0
    for item in items:
        total += size(item) + 2
        if total > MAX_SIZE:
            raise ExpressionError(f"a list of more than {MAX_SIZE} characters as text is over the limit")
        result.append(item)
    return result


def _range(*args: int) -> list[int]:
    if any(not isinstance(arg, int) for arg in args):
        raise ExpressionError("range() takes integers")
    numbers = range(*args)
    if len(numbers) > MAX_SIZE // 4:
        raise ExpressionError(f"range() of {len(numbers)} numbers is more than the limit")
    return list(numbers)


def _round(number: Any, digits: int | None = None) -> Any:
    if digits is not None and (not isinstance(digits, int) or abs(digits) > 400):
        raise ExpressionError("round()'s digits must be an integer between -400 and 400")
    return round(number) if digits is None else round(number, digits)


def _map(function: Any, *sequences: Any) -> list:
    if not isinstance(function, Function):
        raise ExpressionError("map() takes one of the documented functions")
    return _bounded_list(map(function, *sequences))


def _sorted(items: Any, *, reverse: bool = False) -> list:
    return sorted(_bounded_list(items), reverse=bool(reverse))


def _safe(name: str, body: Callable[..., Any]) -> Function:
    def call(*args: Any, **kwargs: Any) -> Any:
        for arg in (*args, *kwargs.values()):
            if isinstance(arg, Function | Namespace) and name not in ("map", "str", "bool"):
                raise ExpressionError(f"{name}() of a function or namespace is not in the language")
        return body(*args, **kwargs)

    return Function(name, call)


_BODIES: dict[str, Callable[..., Any]] = {
    "abs": abs,
    "bool": bool,
    "dict": lambda *args, **kwargs: dict(*args, **kwargs),
    "float": float,
    "int": int,
    "len": len,
    "list": lambda items=(): _bounded_list(items),
    "map": _map,
    "max": max,
    "min": min,
    "range": _range,
    "round": _round,
    "sorted": _sorted,
    "str": str,
}
#: The builtins a xacro expression may call (xacro's documented set, plus ``abs``), each
#: bounded: ``list``/``dict``/``sorted``/``map``/``range`` build at most :data:`MAX_SIZE`.
BUILTINS: dict[str, Function] = {name: _safe(name, body) for name, body in _BODIES.items()}
#: The math functions and constants (also reachable as ``math.NAME``).
MATH: dict[str, Any] = {name: Function(name, getattr(math, name)) for name in MATH_FUNCTIONS} | {
    name: getattr(math, name) for name in MATH_CONSTANTS
}


def base_names(extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The names every expression sees: ``True``/``False``, :data:`MATH` (bare and as
    ``math.``), :data:`BUILTINS`, and ``extra`` (e.g. a ``xacro`` namespace).

    Args:
        extra: More names (``None``: none).
    """
    names: dict[str, Any] = {"True": True, "False": False, "math": Namespace(MATH)}
    names.update(MATH)
    names.update(BUILTINS)
    names.update(extra or {})
    return names
