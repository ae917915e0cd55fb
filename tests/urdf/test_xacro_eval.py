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


#: Each refusal's whole message (after "the expression '...': "), so a refusal that still
#: happens for another reason, or says less, is noticed.
REFUSALS = [
    ("lambda: 0", "a lambda is not in the language"),
    ("(x for x in lengths)", "a generator is not in the language"),
    ("[x for x in lengths]", "a comprehension is not in the language"),
    ("{x for x in lengths}", "a comprehension is not in the language"),
    ("{x: 1 for x in lengths}", "a comprehension is not in the language"),
    ("f'{a}'", "an f-string is not in the language"),
    ("(y := 3)", "':=' is not in the language"),
    ("await a", "await is not in the language"),
    ("(yield a)", "yield is not in the language"),
    ("(yield from a)", "yield is not in the language"),
    ("{1, 2}", "a set display is not in the language"),
    ("[*lengths]", "'*' unpacking is not in the language"),
    ("len(*lengths)", "'*' unpacking is not in the language"),
    ("dict(**table)", "'**' arguments are not in the language"),
    ("{**table}", "'**' in a dict display is not in the language"),
    ("a << 3", "the operator LShift is not in the language"),
    ("~a", "the operator Invert is not in the language"),
    ("b'x'", "the literal bytes b'x' is not in the language"),
    ("_hidden", "the name '_hidden' is not in the language (no name starts with '_')"),
    ("math.__dict__", "the attribute '__dict__' is not in the language (no attribute starts with '_')"),
    ("table._mass", "the attribute '_mass' is not in the language (no attribute starts with '_')"),
    ("table.nothing", "'nothing' is not defined there"),
    ("side.upper", "the attribute .upper of a str is not in the language"),
    ("a[0]", "indexing a int is not in the language"),
    ("math['pi']", "indexing a Namespace is not in the language"),
    ("table[(1, 2)]", "a dict key must be a string or number, not tuple"),
    ("lengths[side]", "a list index must be an integer or a slice"),
    ("lengths[0:side]", "slice bounds must be integers"),
    ("lengths[0:1, 2]", "a Slice expression is not in the language"),
    ("side(1)", "calling a str is not in the language (only the documented functions)"),
    ("'%s' % side", "string formatting with % is not in the language"),
    ("(-8) ** 0.5", "the result is a complex number, not a real one"),
    ("2**1000", f"2**1000 is more than the limit of {MAX_INT_BITS} bits"),
    ("2**256", f"an integer of 257 bits is more than the limit of {MAX_INT_BITS} bits"),
    ("2**200 * 2**200", f"the product is more than the limit of {MAX_INT_BITS} bits"),
    ("2**128 * 2**128", f"the product is more than the limit of {MAX_INT_BITS} bits"),
    ("'x' * 600000 + 'y' * 600000", f"the sum is more than the limit of {MAX_SIZE} characters"),
    ("['x' * 600000, 'y' * 600000]", f"a list of more than {MAX_SIZE} characters as text is over the limit"),
]


@pytest.mark.parametrize(("expression", "message"), REFUSALS)
def test_each_refusal_says_what_is_refused_and_why(expression, message):
    with pytest.raises(ExpressionError) as raised:
        ours(expression)
    assert str(raised.value) == f"the expression {expression!r}: {message}"


def test_a_refused_name_starting_with_an_underscore_is_refused_even_when_the_table_has_it():
    names = base_names(PROPERTIES | {"_secret": 1, "box": {"_inner": 2}})
    for expression in ("_secret", "box._inner"):
        with pytest.raises(ExpressionError, match="starts with '_'"):
            evaluate(expression, names.__getitem__)


def test_a_false_comparison_and_the_else_branch_give_their_values():
    assert ours("1 > 2") is False and ours("1 < 2 < 0") is False and ours("a == 3 == a") is True
    assert ours("1 if a < 0 else 2") == 2 and ours("1 if a > 0 else 2") == 1


def test_a_dict_display_gives_its_value_and_its_size_is_bounded():
    assert ours("{'k': a, 'v': [1, side]}") == {"k": 3, "v": [1, "left"]}
    assert ours("{'k': a}.k") == 3
    for expression in ("[{'k': 'x' * 600000}] * 2", "[{'x' * 600000: 1}] * 2"):
        with pytest.raises(ExpressionError, match="repeating a list"):
            ours(expression)


def test_the_bounds_are_sizes_summed_over_every_item():
    for expression in ("['x' * 600000, 'y'] * 2", "['y', 'x' * 600000] * 2", "[True] * 100000", "[None] * 100000"):
        with pytest.raises(ExpressionError, match="repeating a list"):
            ours(expression)


def test_values_just_within_the_bounds_are_computed():
    assert len(ours(f"'x' * {MAX_SIZE}")) == MAX_SIZE
    assert len(ours("'x' * 500000 + 'y' * 500000")) == MAX_SIZE
    assert ours("2**255") == 2**255 and ours("2**128 * 2**127") == 2**255
    assert ours("2.5 * 10**7") == 2.5e7 and ours("10**7 * 2.5") == 2.5e7 and ours("1 ** 1000") == 1
    assert ours("-" * 99 + "1") == -1
    assert ours("1" + " " * 99_999) == 1


def test_an_exponent_tower_is_refused_before_it_is_computed():
    started = time.monotonic()
    for expression in ("2**10**10", "(-2)**10**10", "2**2**100"):
        with pytest.raises(ExpressionError, match=f"more than the limit of {MAX_INT_BITS} bits"):
            ours(expression)
    assert time.monotonic() - started < 1.0


def test_the_nesting_bound_counts_the_depth_of_each_branch_not_the_nodes_before_it():
    with pytest.raises(ExpressionError, match="nested more than 100 deep"):
        ours("[" + "1, " * 200 + "-" * 150 + "1]")
    with pytest.raises(ExpressionError, match="nested more than 100 deep"):
        ours("-" * 60 + "(1 + " + "-" * 60 + "1)")


def test_the_expression_is_shown_whole_up_to_80_characters_then_cut():
    whole = "a / 0.00" + " + 0" * 18
    cut = "a / 0.000" + " + 0" * 18
    assert len(whole) == 80 and len(cut) == 81
    with pytest.raises(ExpressionError) as raised:
        ours(whole)
    assert str(raised.value) == f"the expression {whole!r} failed: ZeroDivisionError: float division by zero"
    with pytest.raises(ExpressionError) as raised:
        ours(cut)
    assert str(raised.value) == f"the expression {cut[:77] + '...'!r} failed: ZeroDivisionError: float division by zero"
    with pytest.raises(ExpressionError) as raised:
        ours("a  /\t 0")
    assert str(raised.value).startswith("the expression 'a / 0' failed")


def test_a_failure_reason_is_cut_at_200_characters_and_an_expression_too_long_is_refused():
    with pytest.raises(ExpressionError) as raised:
        ours("int('x' * 300)")
    reason = str(raised.value).split("failed: ValueError: ", 1)[1]
    assert len(reason) == 200 and reason.startswith("invalid literal for int()")
    with pytest.raises(ExpressionError) as raised:
        ours("1" + " " * 100_000)
    assert str(raised.value).endswith(": the expression is longer than 100000 characters")


def test_a_function_shows_its_own_name():
    assert ours("str(min)") == "<function min>"


@pytest.mark.parametrize(
    ("item", "most"),
    # A list's text is 2 characters of brackets and, per item, 2 of separator plus the
    # item's own: a character a character, a float, a bool or a function 24, an integer a
    # digit per 3 bits (+2).
    [("'x'", 200_000), ("1.5", 35_714), ("True", 35_714), ("min", 35_714), ("2**30", 62_500)],
)
def test_a_repeated_list_is_bounded_by_its_items_text(item, most):
    assert len(ours(f"[{item}] * {most}")) == most
    with pytest.raises(ExpressionError, match="repeating a list"):
        ours(f"[{item}] * {most + 1}")


@pytest.mark.slow
def test_lists_built_by_functions_count_their_items_towards_the_total_built():
    """Each list of 333,000 one-character strings is about 1,000,000 characters as text:
    sixteen of them are past the 20,000,000 an expression may build, though each is within."""
    item = "len(list('x' * 333000))"
    with pytest.raises(ExpressionError, match="builds more than 20000000 characters"):
        ours("[" + ", ".join([item] * 16) + "]")
    assert ours("[" + ", ".join([item] * 2) + "]") == [333_000, 333_000]
