"""Expanding a xacro robot description into URDF text: the ``xacro`` package for the XML,
robodyn's own evaluator for every expression.

**Why the xacro package stays.** Its XML work — macros with block parameters, properties
with lazy evaluation and scopes, ``<xacro:arg>``, includes with namespaces, ``xacro:if`` —
is what users' files are written against, and re-implementing it would change what
legitimate files expand to. What is unsafe in it is small and sits at a few module-level
names, which :func:`_patched` replaces for the duration of one expansion (under a lock:
xacro keeps global state):

- ``safe_eval`` (every ``${...}``) and ``substitution_args._eval`` (``$(eval ...)``) →
  :func:`robodyn.urdf.xacro_eval.evaluate`, an allow-list over Python's syntax tree (the
  language is stated there), never Python's ``eval``;
- ``_global_symbols`` (the names expressions see) → the evaluator's math and builtins plus a
  ``xacro`` namespace of ``arg``, ``load_yaml``, ``tokenize``, ``dotify``, ``message``,
  ``warning``, ``error``, ``fatal`` — no ``python.*``, no ``abs_filename``;
- ``load_yaml``, ``<xacro:include>`` (``get_include_files``, ``parse``), ``$(env)`` /
  ``$(optenv)`` and ``$(find)`` → :class:`robodyn.urdf.xacro_guard.XacroGuard` and the
  package lookup: files only inside the top file's folder tree, the packages and the zoo,
  read by robodyn's reader; the environment only with ``xacro_env=True``;
- ``eval_all`` / ``eval_text`` are wrapped to count elements, nesting and the text produced
  (the URDF size cap applies as the expansion grows).

What xacro would print (warnings, ``xacro.message``) is re-issued as one
:class:`~robodyn.exceptions.RobodynWarning`; any failure or refusal is one
:class:`~robodyn.exceptions.URDFError` sentence, never xacro's ``sys.exit``. This module
does not import Pinocchio.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import threading
import warnings
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from robodyn.common.text import printable
from robodyn.exceptions import RobodynError, RobodynWarning, URDFError
from robodyn.urdf.packages import PackageLookup
from robodyn.urdf.xacro_eval import ExpressionError, Function, Namespace, evaluate
from robodyn.urdf.xacro_guard import XacroGuard
from robodyn.urdf.xacro_names import base_names

_LOCK = threading.Lock()
XACRO_NAMESPACE = "http://www.ros.org/wiki/xacro"

_XACRO_ROOT = re.compile(r"<robot\b[^>]*\bxmlns:xacro\s*=", re.DOTALL)
_XACRO_USE = re.compile(r"<xacro:|\$\{|\$\(")


def is_xacro_text(text: str) -> bool:
    """Whether URDF-looking text is meant for xacro: its ``<robot>`` root declares the xacro
    namespace (``xmlns:xacro=...``) *and* the text uses xacro (a ``<xacro:...>`` element, a
    ``${...}`` or a ``$(...)``). A URDF that only declares the namespace is plain URDF.

    Args:
        text: The document's text.
    """
    return bool(_XACRO_ROOT.search(text[:20000])) and bool(_XACRO_USE.search(text))


def expand_xacro(
    *,
    path: Path | None,
    text: str | None,
    label: str,
    args: Mapping[str, str] | None,
    lookup: PackageLookup,
    read_file: Callable[[Path], str],
    limit: int,
    env: bool = False,
) -> str:
    """The URDF text a xacro document expands to.

    Args:
        path: The xacro file (its includes are relative to its folder), or ``None``.
        text: The xacro text when there is no file (relative includes start from the
            working folder, and must still be inside a package or the zoo).
        label: The source's name for messages.
        args: Values of ``<xacro:arg>`` arguments, ``{name: value}`` (strings).
        lookup: Where ``$(find NAME)`` looks; its folders are where files may be read.
        read_file: Reads one file (the top file, each include, a YAML file) as text,
            refusing what robodyn refuses (special files, the size cap, not UTF-8).
        limit: The URDF size cap, in bytes, applied to the expansion as it grows.
        env: Whether ``$(env NAME)`` / ``$(optenv NAME)`` may read the environment.

    Raises:
        URDFError: One sentence naming what failed or was refused: an expression outside
            robodyn's xacro language or over its bounds, a file outside the allowed
            folders, the environment without ``env``, an unresolved package, a missing
            include, a bad macro call, an undefined argument, bad XML, a runaway expansion.

    Warns:
        RobodynWarning: With what xacro printed, if anything.
    """
    import xacro

    roots = ((path.parent,) if path is not None else ()) + tuple(folder for _, folder in lookup.explicit)
    guard = XacroGuard(label=label, roots=roots + lookup.ros_path + lookup.zoo_dirs, read_file=read_file, limit=limit, env=env)
    mappings = {str(name): str(value) for name, value in (args or {}).items()}
    captured = io.StringIO()
    with (
        _LOCK,
        _patched(xacro, lookup, guard, label),
        contextlib.redirect_stdout(captured),
        contextlib.redirect_stderr(captured),
    ):
        try:
            if path is not None:
                document = xacro.process_file(str(path), mappings=mappings)
            else:
                xacro.init_stacks(None)
                document = xacro.parse(_declaration_first(text or ""))
                xacro.process_doc(document, mappings=mappings)
            expanded = document.toprettyxml(indent="  ")
        except Exception as error:  # xacro raises many kinds (its own, expat's, robodyn's, wrapped)
            raise _refusal(xacro, error, label) from None
        finally:
            xacro.substitution_args_context["arg"] = {}
    printed = " ".join(line.strip() for line in captured.getvalue().splitlines() if line.strip())
    if printed:
        warnings.warn(printable(f"{label}: xacro says: {printed[:500]}"), RobodynWarning, stacklevel=3)
    return expanded


def _declaration_first(text: str) -> str:
    """The text with blank lines before an ``<?xml ...?>`` declaration removed (urdfdom,
    pybullet and Drake accept them; expat does not)."""
    stripped = text.lstrip("\ufeff \t\r\n")
    return stripped if stripped.startswith("<?xml") else text


def _refusal(xacro: Any, error: Exception, label: str) -> URDFError:
    """One sentence for a xacro failure: robodyn's own refusal if one is inside, else xacro's."""
    inner: BaseException | None = error
    for _ in range(20):  # xacro wraps an exception in its own, sometimes several times
        if inner is None or isinstance(inner, RobodynError | ExpressionError):
            break
        inner = getattr(inner, "exc", None) or inner.__cause__ or inner.__context__
    if isinstance(inner, URDFError):
        return inner
    if isinstance(inner, RobodynError):
        return URDFError(label, str(inner))
    return URDFError(label, _reason(xacro, inner if isinstance(inner, ExpressionError) else error))


def _reason(xacro: Any, error: BaseException) -> str:
    """One sentence for a xacro failure, with the macro and file it happened in."""
    from xacro.substitution_args import ArgException

    inner: BaseException | None = error
    for _ in range(10):  # xacro wraps an exception in its own, sometimes twice
        if inner is None or isinstance(inner, ArgException):
            break
        inner = getattr(inner, "exc", None) or inner.__context__
    if isinstance(inner, ArgException):
        return f"xacro: undefined argument {str(inner)!r} (xacro_args= gives its value)"
    if isinstance(error, RecursionError):
        return "xacro: the document is nested too deeply to expand"
    message = " ".join((str(error) or repr(error)).split())
    stack = [str(item) for item in (xacro.filestack or []) if item]
    where = f" (in {stack[-1]})" if stack else ""
    macros = [m.body.getAttribute("name") for m in (xacro.macrostack or [])]
    inside = f" in macro {macros[-1]!r}" if macros else ""
    return f"xacro: {message[:400]}{inside}{where}"


def _symbols(xacro: Any, guard: XacroGuard) -> dict[str, Any]:
    """The names a ``${...}`` expression sees (xacro's global symbols, made safe)."""

    def say(kind: Callable[..., Any]) -> Callable[..., str]:
        def call(*args: Any) -> str:
            kind(" ".join(str(arg) for arg in args))
            return ""

        return call

    def fatal(*args: Any) -> None:
        raise ExpressionError("xacro.fatal: " + " ".join(str(arg) for arg in args)[:300])

    def load_yaml(filename: str) -> Any:
        return guard.load_yaml(xacro.abs_filename_spec(str(filename)))

    def arg(name: str) -> Any:
        try:
            return xacro.substitution_args_context["arg"][name]
        except KeyError:
            raise ExpressionError(f"undefined argument {name!r} (xacro_args= gives its value)") from None

    def tokenize(text: str, sep: str = ",; ", skip_empty: bool = True) -> list[str]:
        """xacro.tokenize, its separators taken as characters (never as a pattern)."""
        parts = re.split(f"[{re.escape(str(sep))}]", str(text)) if sep else [str(text)]
        return [part for part in parts if part] if skip_empty else parts

    functions: dict[str, Callable[..., Any]] = {
        "arg": arg,
        "load_yaml": load_yaml,
        "tokenize": tokenize,
        "dotify": lambda mapping: dict(mapping),
        "message": say(xacro.message),
        "warning": say(xacro.warning),
        "error": say(xacro.error),
        "fatal": fatal,
    }
    namespace = Namespace({name: Function(f"xacro.{name}", body) for name, body in functions.items()})
    return base_names({"xacro": namespace, "load_yaml": namespace["load_yaml"]})


def _substitution_eval(xacro: Any, guard: XacroGuard, find: Callable[[str], str]) -> Callable[[str, dict], str]:
    """``$(eval EXPR)`` with robodyn's evaluator: xacro's names (``arg``, ``find``,
    ``env``/``optenv`` with the opt-in, math, a few builtins) then the arguments."""
    from xacro.substitution_args import _eval_arg, convert_value

    def evaluate_substitution(expression: str, context: dict) -> str:
        arguments = context.setdefault("arg", {})
        functions: dict[str, Callable[..., Any]] = {
            "arg": lambda name: convert_value(_eval_arg(name, args=arguments), "auto"),
            "find": find,
            "env": guard.environment,
            "optenv": lambda name, default="": guard.environment(name, default),
        }
        names = base_names({"true": True, "false": False}) | {name: Function(name, body) for name, body in functions.items()}

        def lookup(name: str) -> Any:
            return names[name] if name in names else convert_value(arguments[name], "auto")

        return str(evaluate(expression, lookup))

    return evaluate_substitution


@contextlib.contextmanager
def _patched(xacro: Any, lookup: PackageLookup, guard: XacroGuard, label: str) -> Iterator[None]:
    """xacro with robodyn's evaluator, file access, ``$(find)`` and bounds; restored afterwards."""
    from xacro import substitution_args

    def find(name: str) -> str:
        return str(lookup.require(name, label))

    originals = {"parse": xacro.parse, "eval_all": xacro.eval_all, "eval_text": xacro.eval_text}

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            top = len(xacro.filestack or []) <= 1
            try:
                inp = guard.read_file(Path(os.path.join(xacro.root_dir, filename)))
            except URDFError as error:
                raise URDFError(label, error.rule if top else f"the xacro include {filename}: {error.rule}") from None
            inp = _declaration_first(inp)
        return originals["parse"](inp, filename)

    def eval_all(node: Any, macros: Any, symbols: Any) -> Any:
        guard.element(len(xacro.macrostack or []), len(xacro.filestack or []))
        return originals["eval_all"](node, macros, symbols)

    def eval_text(text: Any, symbols: Any) -> Any:
        value = originals["eval_text"](text, symbols)
        guard.text(value)
        return value

    def safe_eval(expression: str, symbols: Any, locals: Any = None) -> Any:
        return evaluate(expression, symbols.__getitem__)

    def include_files(spec: Any, symbols: Any) -> Iterator[str]:
        for name in guard.include_files(xacro.abs_filename_spec(str(xacro.eval_text(spec, symbols)))):
            xacro.all_includes.append(name)
            yield name

    replacements = [
        (xacro, "parse", parse),
        (xacro, "eval_all", eval_all),
        (xacro, "eval_text", eval_text),
        (xacro, "safe_eval", safe_eval),
        (xacro, "get_include_files", include_files),
        (xacro, "_global_symbols", _symbols(xacro, guard)),
        (substitution_args, "_eval_find", find),
        (substitution_args, "_eval_env", guard.environment),
        (substitution_args, "_eval_optenv", lambda name, default="": guard.environment(name, default)),
        (substitution_args, "_eval", _substitution_eval(xacro, guard, find)),
    ]
    saved = [(owner, name, getattr(owner, name)) for owner, name, _ in replacements]
    saved_find = substitution_args._eval_dict["find"]
    try:
        for owner, name, value in replacements:
            setattr(owner, name, value)
        substitution_args._eval_dict["find"] = find
        yield
    finally:
        for owner, name, value in saved:
            setattr(owner, name, value)
        substitution_args._eval_dict["find"] = saved_find
