"""robodyn's evaluator of xacro expressions (``${...}`` and ``$(eval ...)``): an allow-list
over Python's syntax tree, never Python's ``eval``.

The language (what xacro documents for robot files, and nothing that reaches Python's
objects):

- literals: numbers (``int``, ``float``), strings, ``True`` / ``False`` / ``None``, and
  list, tuple and dict displays;
- arithmetic ``+ - * / // % **`` on numbers, ``+`` and ``*`` on strings, lists and tuples
  (``%`` on a string — printf formatting — is refused), unary ``+ - not``;
- comparisons (``== != < <= > >= in not in is is not``), ``and`` / ``or``, ``x if c else y``;
- names: properties, macro parameters and arguments (looked up in the caller's table), and
  the functions and constants of :mod:`robodyn.urdf.xacro_names` (``math``, a few builtins);
- ``a.b`` only on a namespace (``math.``, ``xacro.``, an include's ``ns``) or a dict (a
  YAML mapping: ``a.b`` is ``a['b']``); ``a[i]`` / ``a[i:j]`` only on lists, tuples,
  strings and dicts;
- calls only of the functions named here, with plain arguments (no ``*args``).

Everything else is refused before anything is computed: any other attribute (there is no
``getattr``: ``'{0.__class__}'.format``, ``().__class__``, ``python.vars`` have no name to
resolve), lambdas, comprehensions and generators (no frames), f-strings, ``:=``, bit
operations, imports. Values stay within :data:`MAX_INT_BITS` bits (``10**10**10`` is
refused from the exponent before computing) and :data:`MAX_SIZE` characters as text
(``'x'*10**9`` is refused before allocating); float overflow is refused too. Every refusal
is an :class:`ExpressionError` naming the expression and the reason. This module does not
import Pinocchio or the xacro package.
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from typing import Any

from robodyn.exceptions import RobodynError

#: Largest integer, in bits (2**256 ≈ 1.2e77; a robot needs far less).
MAX_INT_BITS = 256
#: Largest value, in characters of its text (a string's length; a list's items summed).
MAX_SIZE = 1_000_000
#: Deepest nesting of an expression's syntax tree.
MAX_DEPTH = 100
#: Longest expression, in characters.
MAX_EXPRESSION = 100_000
#: Most characters one expression may build in all (strings and lists it computes), so a
#: long list of ``len('x' * 999999)`` cannot keep the evaluator busy.
MAX_BUILT = 20 * MAX_SIZE


class ExpressionError(ValueError):
    """A xacro expression robodyn refuses: outside the language, too large, or failing."""


class Function:
    """A function a xacro expression may call (the only callable values)."""

    def __init__(self, name: str, body: Callable[..., Any]):
        self.name, self.body = name, body

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.body(*args, **kwargs)

    def __repr__(self) -> str:
        return f"<function {self.name}>"


class Namespace(dict):
    """Names reached by ``a.b`` (``math.``, ``xacro.``): a plain dict of allowed values."""

    def __repr__(self) -> str:
        return f"<namespace {len(self)} names>"


def size(value: Any, budget: int = MAX_SIZE) -> int:
    """About how many characters ``str(value)`` has, counting at most past ``budget``.

    Args:
        value: The value.
        budget: Where counting stops.
    """
    if isinstance(value, str):
        return len(value)
    if isinstance(value, bool) or value is None or isinstance(value, float):
        return 24
    if isinstance(value, int):
        return value.bit_length() // 3 + 2
    if isinstance(value, list | tuple | dict):
        total = 2
        items = value.items() if isinstance(value, dict) else ((item, None) for item in value)
        for key, item in items:
            total += 2 + size(key, budget - total) + (0 if item is None else size(item, budget - total))
            if total > budget:
                break
        return total
    return 24


def checked(value: Any) -> Any:
    """``value`` if it is a value of the language within the bounds.

    Args:
        value: A value an expression produced.

    Raises:
        ExpressionError: If it is too large, complex, or of another kind.
    """
    if isinstance(value, bool) or value is None or isinstance(value, str | float | Function | Namespace):
        if isinstance(value, str) and len(value) > MAX_SIZE:
            raise ExpressionError(f"a string of {len(value)} characters is more than the limit of {MAX_SIZE}")
        return value
    if isinstance(value, int):
        if value.bit_length() > MAX_INT_BITS:
            raise ExpressionError(f"an integer of {value.bit_length()} bits is more than the limit of {MAX_INT_BITS} bits")
        return value
    if isinstance(value, list | tuple | dict):
        if size(value) > MAX_SIZE:
            raise ExpressionError(f"a {type(value).__name__} of more than {MAX_SIZE} characters as text is over the limit")
        return value
    if isinstance(value, complex):
        raise ExpressionError("the result is a complex number, not a real one")
    raise ExpressionError(f"a value of kind {type(value).__name__} is not in the language")


def _repeat(sequence: Any, count: int) -> Any:
    """``sequence * count``, refused before allocating if it would be too large."""
    if count > 0 and size(sequence) * count > MAX_SIZE:
        raise ExpressionError(f"repeating a {type(sequence).__name__} {count} times is more than the limit of {MAX_SIZE}")
    return sequence * count


def _power(base: Any, exponent: Any) -> Any:
    """``base ** exponent``, an integer power refused from its size before computing."""
    integers = isinstance(base, int) and isinstance(exponent, int)
    if integers and exponent > 0 and abs(base) > 1 and (abs(base).bit_length() - 1) * exponent > MAX_INT_BITS:
        raise ExpressionError(f"{base}**{exponent} is more than the limit of {MAX_INT_BITS} bits")
    return base**exponent


def _multiply(left: Any, right: Any) -> Any:
    if isinstance(left, str | list | tuple) and isinstance(right, int):
        return _repeat(left, right)
    if isinstance(right, str | list | tuple) and isinstance(left, int):
        return _repeat(right, left)
    if isinstance(left, int) and isinstance(right, int) and left.bit_length() + right.bit_length() > MAX_INT_BITS + 1:
        raise ExpressionError(f"the product is more than the limit of {MAX_INT_BITS} bits")
    return left * right


def _add(left: Any, right: Any) -> Any:
    if isinstance(left, str | list | tuple) and size(left) + size(right) > MAX_SIZE:
        raise ExpressionError(f"the sum is more than the limit of {MAX_SIZE} characters")
    return left + right


def _modulo(left: Any, right: Any) -> Any:
    if isinstance(left, str):
        raise ExpressionError("string formatting with % is not in the language")
    return left % right


_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: _add,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: _multiply,
    ast.Div: lambda a, b: a / b,
    ast.FloorDiv: lambda a, b: a // b,
    ast.Mod: _modulo,
    ast.Pow: _power,
}
_UNARY: dict[type, Callable[[Any], Any]] = {ast.UAdd: lambda a: +a, ast.USub: lambda a: -a, ast.Not: lambda a: not a}
_COMPARE: dict[type, Callable[[Any, Any], bool]] = {
    ast.Eq: lambda a, b: a == b,
    ast.NotEq: lambda a, b: a != b,
    ast.Lt: lambda a, b: a < b,
    ast.LtE: lambda a, b: a <= b,
    ast.Gt: lambda a, b: a > b,
    ast.GtE: lambda a, b: a >= b,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
    ast.Is: lambda a, b: a is b,
    ast.IsNot: lambda a, b: a is not b,
}
_CONTAINERS = (list, tuple, str, dict)


class _Evaluator:
    """One expression's evaluation: ``lookup(name)`` gives a name's value (raises ``KeyError``)."""

    def __init__(self, lookup: Callable[[str], Any]):
        self.lookup = lookup
        self.depth = 0
        self.built = 0

    def _count(self, value: Any) -> Any:
        """``value``, its size counted towards :data:`MAX_BUILT` if it is text or a container."""
        if isinstance(value, str | list | tuple | dict) and not isinstance(value, Namespace):
            self.built += len(value) if isinstance(value, str) else size(value)
            if self.built > MAX_BUILT:
                raise ExpressionError(f"the expression builds more than {MAX_BUILT} characters in all")
        return value

    def value(self, node: ast.AST) -> Any:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(f"the expression is nested more than {MAX_DEPTH} deep")
        try:
            method = getattr(self, "_" + type(node).__name__, None)
            if method is None:
                raise ExpressionError(f"{_describe(node)} is not in the language")
            return checked(method(node))
        finally:
            self.depth -= 1

    def _Constant(self, node: ast.Constant) -> Any:
        if node.value is None or isinstance(node.value, bool | int | float | str):
            return node.value
        raise ExpressionError(f"the literal {type(node.value).__name__} {node.value!r:.40} is not in the language")

    def _Name(self, node: ast.Name) -> Any:
        if node.id.startswith("_"):
            raise ExpressionError(f"the name {node.id!r} is not in the language (no name starts with '_')")
        try:
            return self.lookup(node.id)
        except KeyError:
            raise ExpressionError(f"the name {node.id!r} is not defined") from None

    def _Attribute(self, node: ast.Attribute) -> Any:
        owner = self.value(node.value)
        return _member(owner, node.attr)

    def _Subscript(self, node: ast.Subscript) -> Any:
        owner = self.value(node.value)
        if not isinstance(owner, _CONTAINERS) or isinstance(owner, Namespace):
            raise ExpressionError(f"indexing a {type(owner).__name__} is not in the language")
        key = self.value(node.slice) if not isinstance(node.slice, ast.Slice) else self._slice(node.slice)
        if isinstance(owner, dict):
            if not isinstance(key, str | int | float | bool) and key is not None:
                raise ExpressionError(f"a dict key must be a string or number, not {type(key).__name__}")
            return owner[key]
        if not isinstance(key, int | slice):
            raise ExpressionError(f"a {type(owner).__name__} index must be an integer or a slice")
        return owner[key]

    def _slice(self, node: ast.Slice) -> slice:
        parts = [None if part is None else self.value(part) for part in (node.lower, node.upper, node.step)]
        if any(part is not None and (not isinstance(part, int)) for part in parts):
            raise ExpressionError("slice bounds must be integers")
        return slice(*parts)

    def _BinOp(self, node: ast.BinOp) -> Any:
        operation = _BINARY.get(type(node.op))
        if operation is None:
            raise ExpressionError(f"the operator {type(node.op).__name__} is not in the language")
        return self._count(operation(self.value(node.left), self.value(node.right)))

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        operation = _UNARY.get(type(node.op))
        if operation is None:
            raise ExpressionError(f"the operator {type(node.op).__name__} is not in the language")
        return operation(self.value(node.operand))

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        result: Any = None
        for operand in node.values:
            result = self.value(operand)
            if isinstance(node.op, ast.And) != bool(result):  # `and` stops at a false, `or` at a true value
                return result
        return result

    def _Compare(self, node: ast.Compare) -> Any:
        left = self.value(node.left)
        for operator, comparator in zip(node.ops, node.comparators, strict=True):
            right = self.value(comparator)
            if not _COMPARE[type(operator)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.value(node.body) if self.value(node.test) else self.value(node.orelse)

    def _List(self, node: ast.List) -> Any:
        return [self.value(item) for item in _plain(node.elts)]

    def _Tuple(self, node: ast.Tuple) -> Any:
        return tuple(self.value(item) for item in _plain(node.elts))

    def _Dict(self, node: ast.Dict) -> Any:
        if any(key is None for key in node.keys):
            raise ExpressionError("'**' in a dict display is not in the language")
        return {self.value(key): self.value(item) for key, item in zip(node.keys, node.values, strict=True) if key}

    def _Call(self, node: ast.Call) -> Any:
        function = self.value(node.func)
        if not isinstance(function, Function):
            raise ExpressionError(f"calling a {type(function).__name__} is not in the language (only the documented functions)")
        if any(keyword.arg is None for keyword in node.keywords):
            raise ExpressionError("'**' arguments are not in the language")
        args = [self.value(item) for item in _plain(node.args)]
        kwargs = {str(keyword.arg): self.value(keyword.value) for keyword in node.keywords}
        return self._count(function(*args, **kwargs))


def _plain(items: list[ast.expr]) -> list[ast.expr]:
    if any(isinstance(item, ast.Starred) for item in items):
        raise ExpressionError("'*' unpacking is not in the language")
    return items


def _describe(node: ast.AST) -> str:
    kinds = {
        "Lambda": "a lambda",
        "GeneratorExp": "a generator",
        "ListComp": "a comprehension",
        "SetComp": "a comprehension",
        "DictComp": "a comprehension",
        "JoinedStr": "an f-string",
        "FormattedValue": "an f-string",
        "NamedExpr": "':='",
        "Await": "await",
        "Yield": "yield",
        "YieldFrom": "yield",
        "Set": "a set display",
        "Starred": "'*' unpacking",
    }
    return kinds.get(type(node).__name__, f"a {type(node).__name__} expression")


def _member(owner: Any, name: str) -> Any:
    """``owner.name``: a namespace's name or a dict's key, nothing else."""
    if name.startswith("_"):
        raise ExpressionError(f"the attribute {name!r} is not in the language (no attribute starts with '_')")
    if isinstance(owner, dict):  # a Namespace, a YAML mapping, an include's ns table
        try:
            return owner[name]
        except (KeyError, AttributeError):
            raise ExpressionError(f"{name!r} is not defined there") from None
    raise ExpressionError(f"the attribute .{name} of a {type(owner).__name__} is not in the language")


def evaluate(expression: str, lookup: Callable[[str], Any]) -> Any:
    """The value of a xacro expression.

    Args:
        expression: The text inside ``${...}`` (or after ``$(eval``).
        lookup: A name's value (properties, arguments, the allowed functions); raises
            ``KeyError`` for an unknown name.

    Raises:
        ExpressionError: Naming the expression and why it is refused or failed.
    """
    shown = " ".join(expression.split())
    shown = shown if len(shown) <= 80 else shown[:77] + "..."
    try:
        if len(expression) > MAX_EXPRESSION:
            raise ExpressionError(f"the expression is longer than {MAX_EXPRESSION} characters")
        tree = ast.parse(expression.strip(), mode="eval")
        return _Evaluator(lookup).value(tree.body)
    except RobodynError:  # a refusal of a function the expression called (a file, the environment)
        raise
    except ExpressionError as error:
        raise ExpressionError(f"the expression {shown!r}: {error}") from None
    except SyntaxError as error:
        raise ExpressionError(f"the expression {shown!r} is not valid ({error.msg})") from None
    except (ArithmeticError, ValueError, TypeError, LookupError, RecursionError, MemoryError) as error:
        reason = " ".join(str(error).split())[:200] or type(error).__name__
        raise ExpressionError(f"the expression {shown!r} failed: {type(error).__name__}: {reason}") from None
