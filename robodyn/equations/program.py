"""Straight-line programs: the form every derived quantity of the equations layer takes.

A :class:`Program` is a list of assignments ``symbol = expression`` in evaluation order
(each expression uses the inputs and the symbols assigned before it) and named outputs,
expressions in the same symbols. It has no loops, branches or calls, so anything that can
walk a list can work on it:

- print it (:mod:`robodyn.equations.c_printer` writes C, the renderers text, LaTeX, JSON
  and Python), or evaluate it (:func:`evaluate`);
- keep only what some outputs need (:func:`needed`), shorten it
  (:mod:`robodyn.equations.sharing`);
- (later) differentiate it forward, assignment by assignment (``dx = Σ ∂e/∂y dy``), or
  rebuild it as a CasADi or JAX graph, one node an assignment.

:class:`ProgramBuilder` makes one: ``let(expr)`` names a non-trivial expression and
returns its symbol (a number, a symbol or number × symbol is returned as it is).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

Assignment = tuple[sp.Symbol, sp.Expr]


@dataclass(frozen=True)
class Program:
    """Inputs, assignments in evaluation order, and named outputs.

    Attributes:
        inputs: Name -> input symbols, e.g. ``{"q": (...), "qd": (...), "qdd": (...)}``;
            every free symbol of the program is an input or an assigned symbol.
        assignments: ``(symbol, expression)`` pairs; an expression uses inputs and symbols
            assigned before it.
        outputs: Name -> output expressions, e.g. ``{"tau": (...)}`` (a matrix row-major).
        parameters: Input symbols that stand for physical constants (``keep_params``), with
            their values; ``labels`` gives each one's ``(kind, owner, component)``.
    """

    inputs: dict[str, tuple[sp.Symbol, ...]]
    assignments: tuple[Assignment, ...]
    outputs: dict[str, tuple[sp.Expr, ...]]
    parameters: dict[sp.Symbol, float] = field(default_factory=dict)
    labels: dict[sp.Symbol, tuple[str, str, str]] = field(default_factory=dict)

    def output_expressions(self) -> list[sp.Expr]:
        """Every output expression, the outputs in order."""
        return [expr for exprs in self.outputs.values() for expr in exprs]

    def with_outputs(self, flat: Sequence[sp.Expr], assignments: Iterable[Assignment]) -> Program:
        """The program with new assignments and its outputs replaced, in order, by ``flat``.

        Args:
            flat: Every output entry, in the order of :attr:`outputs` (names, then entries).
            assignments: The new assignments, each after the symbols it uses.
        """
        outputs, start = {}, 0
        for name, exprs in self.outputs.items():
            outputs[name] = tuple(flat[start : start + len(exprs)])
            start += len(exprs)
        return Program(self.inputs, tuple(assignments), outputs, self.parameters, self.labels)


def trivial(expr: sp.Expr) -> bool:
    """Whether an expression is not worth a variable: a number, a symbol, or number × symbol.

    Args:
        expr: A sympy expression.
    """
    return bool(
        expr.is_Number
        or expr.is_Symbol
        or (expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number and expr.args[1].is_Symbol)
    )


def _symbols_and_powers(expr: sp.Expr) -> tuple[set[sp.Basic], set[sp.Basic]]:
    """An expression's symbols, and the bases of its powers (one walk each, not one a pair)."""
    return expr.free_symbols, {power.base for power in expr.atoms(sp.Pow)}


class ProgramBuilder:
    """Collects assignments; a variable is made only for a non-trivial expression.

    Every expression is expanded; with ``pythagoras``, ``c² = 1 − s²`` (or ``s² = 1 − c²``)
    is used for every registered pair (:meth:`pair`) where that makes it shorter.
    Names are ``<prefix><counter>`` (the counter runs over the whole program).
    """

    def __init__(self, *, pythagoras: bool = False) -> None:
        self.assignments: list[Assignment] = []
        self.pythagoras = pythagoras
        self.pairs: list[tuple[sp.Symbol, sp.Symbol]] = []  # (cos, sin) of a joint
        self._counter = 0

    def pair(self, c: sp.Expr, s: sp.Expr) -> None:
        """Register ``c = cos x``, ``s = sin x`` (used with ``pythagoras`` only).

        Args:
            c: The symbol of a cosine.
            s: The symbol of the sine of the same angle.
        """
        if self.pythagoras and c.is_Symbol and s.is_Symbol:
            self.pairs.append((c, s))

    def rewrite(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` expanded, with ``c² + s² = 1`` used where shorter (see the class).

        Args:
            expr: A sympy expression.
        """
        expr = sp.expand(expr)
        present, powered = _symbols_and_powers(expr) if self.pairs else (set(), set())
        for c, s in self.pairs:
            # c or s absent, or neither under a power: both substitutions would change nothing
            if c not in present or s not in present or not {c, s} & powered:
                continue
            options = [expr, sp.expand(expr.subs(c**2, 1 - s**2)), sp.expand(expr.subs(s**2, 1 - c**2))]
            expr = min(options, key=sp.count_ops)
            present, powered = _symbols_and_powers(expr)
        return expr

    def let(self, expr: sp.Expr, prefix: str = "x") -> sp.Expr:
        """A new symbol for ``expr`` (rewritten), or ``expr`` itself where trivial.

        Args:
            expr: A sympy expression.
            prefix: The new symbol's name before its number.
        """
        expr = self.rewrite(expr)
        if trivial(expr):
            return expr
        self._counter += 1
        symbol = sp.Symbol(f"{prefix}{self._counter}", real=True)
        self.assignments.append((symbol, expr))
        return symbol

    def vector(self, values: Iterable[sp.Expr], prefix: str) -> sp.Matrix:
        """:meth:`let` of every entry, as a column.

        Args:
            values: The entries.
            prefix: The new symbols' name before their number.
        """
        return sp.Matrix([self.let(v, prefix) for v in values])

    def matrix(self, matrix: sp.Matrix, prefix: str) -> sp.Matrix:
        """:meth:`let` of every entry.

        Args:
            matrix: A sympy matrix.
            prefix: The new symbols' name before their number.
        """
        return sp.Matrix(matrix.rows, matrix.cols, lambda i, j: self.let(matrix[i, j], prefix))

    def program(self, inputs: dict[str, tuple[sp.Symbol, ...]], outputs: dict[str, Sequence[sp.Expr]]) -> Program:
        """The program so far, with ``outputs`` rewritten like the assignments.

        Args:
            inputs: The input symbols by name.
            outputs: The output expressions by name.
        """
        rewritten = {name: tuple(self.rewrite(e) for e in exprs) for name, exprs in outputs.items()}
        return Program(inputs, tuple(self.assignments), rewritten)


def needed(assignments: Sequence[Assignment], outputs: Iterable[sp.Expr]) -> list[Assignment]:
    """The assignments the outputs depend on, in their original order.

    Args:
        assignments: ``(symbol, expression)`` pairs, each after the symbols it uses.
        outputs: The expressions wanted.
    """
    wanted: set[sp.Basic] = set().union(*(sp.sympify(expr).free_symbols for expr in outputs))
    kept = []
    for symbol, expr in reversed(assignments):
        if symbol in wanted:
            kept.append((symbol, expr))
            wanted |= expr.free_symbols
    return kept[::-1]


def in_order(definitions: Mapping[sp.Symbol, sp.Expr], outputs: Iterable[sp.Expr]) -> list[Assignment]:
    """The definitions the outputs depend on, each after everything it uses.

    Args:
        definitions: Expression of each defined symbol (in any order).
        outputs: The expressions wanted.
    """
    ordered: list[Assignment] = []
    state: dict[sp.Symbol, int] = {}  # 1: in progress, 2: done
    roots = sorted({s for e in outputs for s in e.free_symbols if s in definitions}, key=str)
    for root in roots:
        stack = [(root, False)]
        while stack:
            symbol, expanded = stack.pop()
            if state.get(symbol) == 2:
                continue
            if expanded:
                state[symbol] = 2
                ordered.append((symbol, definitions[symbol]))
                continue
            state[symbol] = 1
            stack.append((symbol, True))
            for dependency in sorted(definitions[symbol].free_symbols, key=str):  # sorted: the same order every run
                if dependency in definitions and state.get(dependency) != 2:
                    stack.append((dependency, False))
    return ordered


def operation_count(program: Program) -> int:
    """``sympy.count_ops`` over every assignment and output (numbers as they are).

    Args:
        program: The program.
    """
    expressions = [e for _, e in program.assignments] + program.output_expressions()
    return int(sum(sp.count_ops(e) for e in expressions))


def evaluate(program: Program, values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The outputs at one point, in floating point.

    Args:
        program: The program (no kept parameters left as inputs without a value).
        values: Input name -> numbers, one per symbol of ``program.inputs[name]``; kept
            parameters take their :attr:`Program.parameters` values.

    Returns:
        Output name -> array of its expressions' values, shape (len(outputs[name]),).
    """
    names: dict[sp.Symbol, sp.Symbol] = {}
    arguments: list[float] = []
    for name, symbols in program.inputs.items():
        numbers = np.asarray(values[name], dtype=float).reshape(-1)
        for symbol, number in zip(symbols, numbers, strict=True):
            names[symbol] = sp.Symbol(f"_in[{len(arguments)}]")
            arguments.append(float(number))
    for symbol, number in program.parameters.items():
        names[symbol] = sp.Symbol(f"_in[{len(arguments)}]")
        arguments.append(float(number))
    names.update({symbol: sp.Symbol(f"_t{index}") for index, (symbol, _) in enumerate(program.assignments)})
    printer = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})
    lines = ["def _program(_in):"]
    lines += [f"    {names[s]} = {printer.doprint(e.xreplace(names))}" for s, e in program.assignments]
    lines.append(f"    return [{', '.join(printer.doprint(e.xreplace(names)) for e in program.output_expressions())}]")
    namespace: dict[str, Any] = {"math": math}
    exec(compile("\n".join(lines), "<program>", "exec"), namespace)  # generated from sympy expressions only
    flat = [float(x) for x in namespace["_program"](arguments)]
    result, start = {}, 0
    for name, exprs in program.outputs.items():
        result[name] = np.array(flat[start : start + len(exprs)])
        start += len(exprs)
    return result
