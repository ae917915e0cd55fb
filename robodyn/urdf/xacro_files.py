"""Expanding a ``.xacro`` robot description into URDF text, with the ``xacro`` package.

The ``xacro`` package (PyPI, works offline) expands macros, properties, ``<xacro:arg>``
arguments, includes and ``$(find pkg)``; robodyn only wires it up:

- ``$(find NAME)`` resolves through robodyn's one package lookup
  (:mod:`robodyn.urdf.packages`: ``packages=``, ``$ROS_PACKAGE_PATH``, the zoo), not ROS's
  ament index;
- every file xacro opens (the top file and each include) is read like a URDF: regular files
  only, at most ``max_bytes`` bytes, UTF-8 (:func:`robodyn.urdf.sources.read_regular_file`);
- what xacro would print (warnings, a macro's ``xacro.message``) is captured and re-issued
  as one :class:`~robodyn.exceptions.RobodynWarning`; any failure is one
  :class:`~robodyn.exceptions.URDFError` sentence (unresolved package, missing include, bad
  macro call, undefined argument), never xacro's ``sys.exit``.

What xacro itself evaluates: ``${...}`` expressions are Python ``eval`` with builtins removed,
names starting with ``__`` refused, and only xacro's namespace (``math``, a few builtins as
``python.*``, ``xacro.load_yaml`` — which reads a YAML file — ``xacro.arg``); ``$(eval ...)``
likewise; ``$(env VAR)`` / ``$(optenv VAR)`` read the environment; ``<xacro:include>`` may
name any XML file on disk (read with the limits above). xacro keeps global state, so
expansions are serialised by a lock. This module does not import Pinocchio.
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
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.packages import PackageLookup

_LOCK = threading.Lock()
XACRO_NAMESPACE = "http://www.ros.org/wiki/xacro"


_XACRO_ROOT = re.compile(r"<robot\b[^>]*\bxmlns:xacro\s*=", re.DOTALL)


def is_xacro_text(text: str) -> bool:
    """Whether URDF-looking text declares the xacro namespace (``xmlns:xacro=...``) on its root."""
    return bool(_XACRO_ROOT.search(text[:20000]))


def expand_xacro(
    *,
    path: Path | None,
    text: str | None,
    label: str,
    args: Mapping[str, str] | None,
    lookup: PackageLookup,
    read_file: Callable[[Path], str],
) -> str:
    """The URDF text a xacro document expands to.

    Args:
        path: The ``.xacro`` file (its includes are relative to its folder), or ``None``.
        text: The xacro text when there is no file (includes relative to the working folder).
        label: The source's name for messages.
        args: Values of ``<xacro:arg>`` arguments, ``{name: value}`` (strings).
        lookup: Where ``$(find NAME)`` looks.
        read_file: Reads one file xacro opens (the top file and each include) as text,
            refusing what robodyn refuses (special files, a size cap, not UTF-8).

    Raises:
        URDFError: One sentence naming what failed: an unresolved package, a missing or
            unreadable include, a bad macro call, an undefined argument, bad XML.

    Warns:
        RobodynWarning: With what xacro printed, if anything.
    """
    import xacro

    mappings = {str(name): str(value) for name, value in (args or {}).items()}
    captured = io.StringIO()
    with (
        _LOCK,
        _patched(xacro, lookup, read_file, label),
        contextlib.redirect_stdout(captured),
        contextlib.redirect_stderr(captured),
    ):
        try:
            if path is not None:
                document = xacro.process_file(str(path), mappings=mappings)
            else:
                xacro.init_stacks(None)
                document = xacro.parse(text)
                xacro.process_doc(document, mappings=mappings)
            expanded = document.toprettyxml(indent="  ")
        except URDFError:
            raise
        except Exception as error:  # xacro raises many kinds (its own, expat's, eval's)
            inner = getattr(error, "exc", None)
            if isinstance(inner, URDFError):  # robodyn's own refusal, wrapped by xacro
                raise inner from None
            raise URDFError(label, _reason(xacro, error)) from None
        finally:
            xacro.substitution_args_context["arg"] = {}
    printed = " ".join(line.strip() for line in captured.getvalue().splitlines() if line.strip())
    if printed:
        warnings.warn(printable(f"{label}: xacro says: {printed[:500]}"), RobodynWarning, stacklevel=3)
    return expanded


def _reason(xacro: Any, error: Exception) -> str:
    """One sentence for a xacro failure, with the file it happened in."""
    from xacro.substitution_args import ArgException

    inner: BaseException | None = error
    for _ in range(10):  # xacro wraps an exception in its own, sometimes twice
        if inner is None or isinstance(inner, ArgException):
            break
        inner = getattr(inner, "exc", None) or inner.__context__
    if isinstance(inner, ArgException):
        return f"xacro: undefined argument {str(inner)!r} (xacro_args= gives its value)"
    message = " ".join((str(error) or repr(error)).split())
    stack = [str(item) for item in (xacro.filestack or []) if item]
    where = f" (in {stack[-1]})" if stack else ""
    macros = [m.body.getAttribute("name") for m in (xacro.macrostack or [])]
    inside = f" in macro {macros[-1]!r}" if macros else ""
    return f"xacro: {message[:400]}{inside}{where}"


@contextlib.contextmanager
def _patched(xacro: Any, lookup: PackageLookup, read_file: Callable[[Path], str], label: str) -> Iterator[None]:
    """xacro with robodyn's ``$(find)`` and file reading, restored afterwards."""
    from xacro import substitution_args

    def find(name: str) -> str:
        return str(lookup.require(name, label))

    original_parse = xacro.parse

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            try:
                inp = read_file(Path(os.path.join(xacro.root_dir, filename)))
            except URDFError as error:
                top = len(xacro.filestack or []) <= 1
                raise URDFError(label, error.rule if top else f"the xacro include {filename}: {error.rule}") from None
        return original_parse(inp, filename)

    saved = (substitution_args._eval_find, substitution_args._eval_dict["find"])
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    xacro.parse = parse
    try:
        yield
    finally:
        substitution_args._eval_find, substitution_args._eval_dict["find"] = saved
        xacro.parse = original_parse
