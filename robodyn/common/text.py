"""Text from a URDF made safe for each output: the one home of every escaping function.

A URDF is untrusted input: its link and joint names, its robot name and its numbers'
text can hold newlines, carriage returns, ANSI escape sequences (``ESC [ 31 m``), C1
control characters (``\\x9b`` is a one-byte CSI on many terminals), Unicode bidi overrides
(U+202E reverses what follows), TeX commands or a docstring's closing quotes. Each output
has one function here, and nothing else in robodyn escapes text:

- :func:`printable` — a terminal or a text file (every message, every report line);
  :func:`quoted` — a name inside a message, like ``repr``; :func:`printable_lines` — a
  multi-line table; :func:`is_printable` — the test;
- :func:`latex_text` — inside ``\\text{}`` / ``\\texttt{}``;
- :func:`json_text` — a JSON document;
- :func:`comment_text` — inside a Python docstring or a C block comment;
- :func:`identifier` — a Python/C/sympy identifier.

Standard library only: :mod:`robodyn.exceptions` imports it, so that every exception
message is escaped by the same function.
"""

from __future__ import annotations

import json
import keyword
import math
import re
from typing import Any

#: Escapes with a name of their own (as ``repr`` writes them); the rest are ``\xNN``,
#: ``\uNNNN`` or ``\UNNNNNNNN``.
_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}
#: Characters a comment may keep: printable ASCII letters, digits and harmless punctuation.
_SAFE_COMMENT = re.compile(r"[A-Za-z0-9 _\-.,:;+=()\[\]<>#@!%&^~|']")
#: Printable ASCII characters that mean something to TeX in text mode, and what writes them.
_LATEX_SPECIAL = {
    "\\": r"\textbackslash{}",
    "{": r"\{",
    "}": r"\}",
    "$": r"\$",
    "&": r"\&",
    "#": r"\#",
    "%": r"\%",
    "_": r"\_",
    "^": r"\textasciicircum{}",
    "~": r"\textasciitilde{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
    "|": r"\textbar{}",
    '"': r"\textquotedbl{}",
    "-": "-{}",
}
#: Names an identifier must not take (besides Python's keywords): the generated code's modules.
_RESERVED = ("np", "math", "sp")


def _escape(character: str) -> str:
    """One unsafe character as a visible escape (``\\n``, ``\\x1b``, ``\\u202e``, ``\\U000e0001``)."""
    if character in _NAMED:
        return _NAMED[character]
    code = ord(character)
    if code <= 0xFF:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code <= 0xFFFF else f"\\U{code:08x}"


def printable(text: object) -> str:
    """``str(text)`` safe on a terminal: one visible line, readable in any script.

    Every character that is not printable by Unicode's rule (:meth:`str.isprintable`) is
    escaped: control characters (C0 with newline and tab, DEL, C1 such as ``\\x9b``), format
    characters (bidi embeddings, overrides and isolates such as U+202E, zero-width
    characters, U+FEFF, tag characters), separators other than the ASCII space (line and
    paragraph separators, no-break spaces), surrogates, private-use and unassigned code
    points. Printable characters of any script are kept. The escapes are ASCII and
    printable, so the result holds no line break and escaping it again changes nothing.

    Args:
        text: Anything; it is converted with :func:`str`.

    Returns:
        The text with ``\\n``, ``\\r``, ``\\t``, ``\\xNN``, ``\\uNNNN`` or ``\\UNNNNNNNN`` in
        place of each unsafe character.
    """
    text = str(text)
    if text.isprintable():  # the common case, at C speed
        return text
    return "".join(c if c.isprintable() else _escape(c) for c in text)


def is_printable(text: str) -> bool:
    """Whether ``text`` is already safe (:func:`printable` would not change it)."""
    return text.isprintable()


def quoted(name: object) -> str:
    """A name from a URDF for a message: in single quotes, escaped like ``repr`` of a str.

    Args:
        name: The name (anything ``str`` takes).
    """
    return "'" + printable(str(name).replace("\\", "\\\\").replace("'", "\\'")) + "'"


def printable_lines(text: object) -> str:
    """Multi-line text (a table, a report) with :func:`printable` applied to each line:
    its own line breaks are kept, any other control character is escaped."""
    return "\n".join(printable(line) for line in str(text).split("\n"))


def _code_point(character: str) -> str:
    return f"<U+{ord(character):04X}>"


def latex_text(text: str) -> str:
    """``text`` for LaTeX's text mode (``\\text{...}``, ``\\texttt{...}``).

    TeX's special characters are written as the commands that print them (``\\$``,
    ``\\textbackslash{}``, ...); every character outside printable ASCII (control
    characters, line breaks, non-ASCII letters) as ``<U+XXXX>``, so the result is ASCII and
    one line whatever the engine and input encoding.

    Args:
        text: Any text (a name from a file).
    """
    out = []
    for character in str(text):
        if character in _LATEX_SPECIAL:
            out.append(_LATEX_SPECIAL[character])
        elif " " <= character <= "~":
            out.append(character)
        else:
            out.append(_code_point(character).replace("<", r"\textless{}").replace(">", r"\textgreater{}"))
    return "".join(out)


def _finite_or_none(value: Any) -> Any:
    """``value`` with every non-finite float as ``None``; numpy values through ``tolist()``."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: _finite_or_none(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_or_none(item) for item in value]
    if not isinstance(value, str | int) and hasattr(value, "tolist"):  # numpy arrays and scalars
        return _finite_or_none(value.tolist())
    return value


def json_text(value: object, *, indent: int | None = 2) -> str:
    """Strict JSON (RFC 8259), ASCII only: every string JSON-escaped with non-ASCII as
    ``\\uXXXX``, a non-finite number (an unlimited limit) as ``null``.

    Args:
        value: Dicts, lists, tuples, strings, numbers, booleans, ``None`` and numpy arrays or
            scalars.
        indent: As for :func:`json.dumps` (``None``: one line).
    """
    return json.dumps(_finite_or_none(value), ensure_ascii=True, allow_nan=False, indent=indent)


def comment_text(text: str) -> str:
    """``text`` safe inside a Python docstring or a C ``/* */`` comment.

    Printable ASCII letters, digits and harmless punctuation are kept; every other
    character (quotes, backslashes, ``*``, ``/``, ``?``, newlines, control characters,
    non-ASCII) is written as ``<U+XXXX>``, so no ``\"\"\"``, ``*/``, ``/*``, trigraph or line
    break can appear.

    Args:
        text: Any text (a name from a file).
    """
    return "".join(c if _SAFE_COMMENT.fullmatch(c) else _code_point(c) for c in str(text))


def identifier(name: str, taken: set[str] | None = None, *, prefix: str = "") -> str:
    """``prefix + name`` as an identifier (``[A-Za-z_][A-Za-z0-9_]*``), unique among ``taken``
    (which it joins).

    Every character outside ``[A-Za-z0-9_]`` becomes ``_`` (a run of them one ``_``); a
    leading digit or an empty result gets ``x``; a Python keyword or a name of the generated
    code's modules gets ``_``; a name already taken gets ``_2``, ``_3``...

    Args:
        name: Any text (a joint, link or robot name).
        taken: Identifiers already used; the result is added to it.
        prefix: Put in front (e.g. ``"q_"``).
    """
    base = prefix + re.sub(r"[^A-Za-z0-9_]+", "_", name.encode("ascii", "replace").decode("ascii"))
    if not base or base[0].isdigit():
        base = "x" + base
    if keyword.iskeyword(base) or base in _RESERVED:
        base += "_"
    taken = set() if taken is None else taken
    candidate, count = base, 1
    while candidate in taken:
        count += 1
        candidate = f"{base}_{count}"
    taken.add(candidate)
    return candidate


def counted(count: int, noun: str, plural: str | None = None) -> str:
    """A count with its noun in the right number: ``"1 value"``, ``"2 values"``, ``"0 errors"``,
    ``"1 degree of freedom"`` (``noun="degree"``, then append the rest).

    Args:
        count: How many.
        noun: The singular noun.
        plural: The plural when it is not ``noun + "s"`` (e.g. ``"entries"``).
    """
    return f"{count} {noun if count == 1 else (plural or noun + 's')}"


__all__ = [
    "comment_text",
    "counted",
    "identifier",
    "is_printable",
    "json_text",
    "latex_text",
    "printable",
    "printable_lines",
    "quoted",
]
