"""robodyn's xacro evaluator: the documented language gives xacro's own values; every escape
xacro's evaluator lets through (checked against it here, as the negative control) is refused;
values past the bounds are refused before they are computed."""

from __future__ import annotations

import math
import time

import pytest
import xacro

from robodyn.urdf.xacro_eval import MAX_INT_BITS, MAX_SIZE, ExpressionError, Namespace, evaluate
from robodyn.urdf.xacro_names import base_names

PROPERTIES = {"a": 3, "b": -0.25, "side": "left", "lengths": [0.3, 0.25, 0.1], "table": {"mass": 1.5, "axes": [0, 1, 0]}}

#: Expressions of the documented language (math, conditionals, comparisons, properties,
#: indexing, the allowed builtins) — evaluated by xacro itself as the reference.
LANGUAGE = [
    "a * 2 + b",
    "-pi / 2",
    "math.pi * radians(90)",
    "sin(0.3) ** 2 + cos(0.3) ** 2",
    "atan2(b, a) - math.atan2(b, a)",
    "sqrt(a ** 2 + 4.0)",
    "degrees(pi) // 7",
    "a % 2",
    "2 ** 10 - 1",
    "1 if a > 2 else 0",
    "'right' if side == 'left' else 'left'",
    "side + '_arm'",
    "side * 2",
    "a > 2 and b < 0 or not a",
    "0 < a <= 3 != 4",
    "lengths[1] + lengths[-1]",
    "lengths[0:2]",
    "len(lengths) * max(lengths) - min(1, 2)",
    "round(b * 3.3333, 3)",
    "int('7') + float('2.5') + int(2.9)",
    "str(a) + str(True)",
    "bool(0) or 'fallback'",
    "table['mass'] * table['axes'][1]",
    "'eft' in side",
    "list(map(float, ['1', '2']))",
    "[a, b, side][2]",
    "(1, 2) + (3,)",
    "dict(x=1)['x']",
    "abs(b) == -b",
    "sorted([3, 1, 2])",
    "None is None",
    "e ** 1 == math.e",
]


def ours(expression: str) -> object:
    names = base_names(PROPERTIES)
    return evaluate(expression, names.__getitem__)


def xacros(expression: str) -> object:
    """xacro 2.x's own evaluator (Python eval over its namespace) — the permissive reference."""
    symbols = dict(xacro._global_symbols)
    symbols.update(PROPERTIES)
    symbols["abs"] = abs  # xacro exposes it as python.abs only
    return xacro.safe_eval(expression, symbols)


@pytest.mark.parametrize("expression", LANGUAGE)
def test_the_documented_language_gives_xacros_own_values(expression):
    assert ours(expression) == xacros(expression)


def test_a_yaml_mapping_reads_by_dots_and_names_reach_math_as_a_namespace():
    assert ours("table.mass + table.axes[1]") == 2.5
    assert ours("math.tau") == math.tau and isinstance(ours("math"), Namespace)


#: Escapes from xacro's evaluator: each returns a Python object (a class, a frame, a
#: function, a mapping of a type's internals, or text made from attributes) under xacro.
ESCAPES = [
    "python.vars(python.type)['__subclasses__'](python.type(()).mro()[-1])",
    "python.type(()).mro()",
    "python.vars(python.type(xacro))",
    "(x for x in [1]).gi_frame.f_globals",
    "[(x for x in [1])][0].gi_frame",
    "(lambda: 0)",
    "'{0.__class__.__mro__}'.format(1)",
    "'%r' % python.type",
    "xacro.abs_filename('x')",
    "xacro.dotify({}).keys",
    "min.__self__",
    "python.vars(python.type(xacro.load_yaml))",
]


def leaked(value: object) -> bool:
    """Whether an evaluation reached Python's objects (anything but plain data, or text
    made from a class)."""
    if isinstance(value, str):
        return "class" in value
    if isinstance(value, list | tuple):
        return any(leaked(item) for item in value)
    return not isinstance(value, int | float | dict) or (isinstance(value, dict) and "__builtins__" in value)


@pytest.mark.parametrize("expression", ESCAPES)
def test_an_escape_through_python_objects_is_refused(expression):
    with pytest.raises(ExpressionError) as raised:
        ours(expression)
    assert "\n" not in str(raised.value) and "the expression" in str(raised.value)


@pytest.mark.parametrize("expression", [e for e in ESCAPES if not e.startswith(("min.", "xacro.abs"))])
def test_negative_control_xacros_own_evaluator_lets_each_escape_through(expression):
    """The check above is real: the same expressions, given to xacro's eval, reach Python."""
    assert leaked(xacros(expression))


@pytest.mark.parametrize(
    ("expression", "reason"),
    [
        ("10**10**10", f"more than the limit of {MAX_INT_BITS} bits"),
        ("2**2**2**2**2", f"more than the limit of {MAX_INT_BITS} bits"),
        ("'x' * 10**9", "repeating a str 1000000000 times"),
        ("10**9 * 'x'", "repeating a str 1000000000 times"),
        ("[[[0] * 1000] * 1000] * 1000", "repeating a list"),
        ("floor(1e300)", "an integer of 997 bits"),
        ("1e308 * 10 - 1e308 * 10 + 10.0 ** 400", "OverflowError"),
        ("range(10**8)", "range() of 100000000 numbers"),
        ("round(1.5, 10**6)", "round()'s digits"),
        ("(-8) ** 0.5", "complex number"),
        ("-" * 5000 + "1", "RecursionError"),
        ("(" * 500 + "1" + ")" * 500, "not valid"),
        ("+".join(["1"] * 300), "nested more than 100 deep"),
        ("[" + ", ".join(["len('x' * 999999)"] * 40) + "]", "builds more than 20000000 characters"),
    ],
)
def test_values_past_the_bounds_are_refused_before_they_are_computed(expression, reason):
    started = time.monotonic()
    with pytest.raises(ExpressionError, match=None) as raised:
        ours(expression)
    assert reason in str(raised.value) and time.monotonic() - started < 1.0


def test_negative_control_the_size_bound_is_what_stops_a_long_string():
    expression = f"'x' * {MAX_SIZE + 1}"
    assert len(xacros(expression)) == MAX_SIZE + 1  # xacro builds it
    with pytest.raises(ExpressionError, match="repeating a str"):
        ours(expression)
    assert len(ours(f"'x' * {MAX_SIZE // 2}")) == MAX_SIZE // 2


@pytest.mark.parametrize(
    "expression",
    [
        "f'{a}'",
        "[x for x in lengths]",
        "{x: 1 for x in lengths}",
        "(y := 3)",
        "a << 3",
        "a ^ 1",
        "~a",
        "{1, 2}",
        "b'bytes'",
        "1j",
        "print(a)",
        "__import__('os')",
        "_hidden",
        "side.upper()",
        "lengths.append(1)",
        "len(*lengths)",
        "dict(**table)",
        "math.__dict__",
        "a[0]",
        "math['pi']",
        "max(lengths, key=abs)",
        "map(lambda x: x, lengths)",
        "'%s' % side",
        "lengths[side]",
    ],
)
def test_syntax_outside_the_language_is_refused_in_one_line(expression):
    with pytest.raises(ExpressionError) as raised:
        ours(expression)
    assert "\n" not in str(raised.value)


def test_an_undefined_name_and_a_failing_operation_are_one_line_each():
    with pytest.raises(ExpressionError, match=r"the name 'python' is not defined"):
        ours("python.vars")
    with pytest.raises(ExpressionError, match=r"ZeroDivisionError"):
        ours("a / 0")
