"""Names from a URDF, made safe for every output format: one function a format.

A joint, link or robot name is text from a file someone downloaded. It reaches the
equations' outputs only through these functions:

- :func:`identifier` — a Python/C/sympy identifier (``[A-Za-z_][A-Za-z0-9_]*``), made
  collision-free against the names already taken;
- :func:`comment_text` — inside a Python docstring or a C block comment: printable ASCII
  letters, digits and harmless punctuation only; every other character (quotes,
  backslashes, ``*``, ``/``, ``?``, newlines, control characters, non-ASCII) is written
  as ``<U+XXXX>``, so no ``\"\"\"``, ``*/``, ``/*``, trigraph or line break can appear;
- :func:`terminal_text` — plain text for a terminal or a text file: control characters
  (C0, DEL, C1, line and paragraph separators) written as ``\\xNN`` / ``\\uXXXX``;
- :func:`latex_text` — text inside ``\\text{}`` / ``\\texttt{}``: TeX's special characters
  escaped, anything else outside printable ASCII as ``<U+XXXX>``;
- :func:`json_text` — ``json.dumps`` (ASCII-only).
"""

from __future__ import annotations

import json
import re
import unicodedata

_SAFE_COMMENT = re.compile(r"[A-Za-z0-9 _\-.,:;+=()\[\]<>#@!%&^~|']")
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


def _code_point(ch: str) -> str:
    return f"<U+{ord(ch):04X}>"


def identifier(name: str, taken: set[str] | None = None, *, prefix: str = "") -> str:
    """``prefix + name`` as an identifier, unique among ``taken`` (which it joins).

    Every character outside ``[A-Za-z0-9_]`` becomes ``_`` (a run of them one ``_``); a
    leading digit or an empty result gets ``x``; a name already taken gets ``_2``, ``_3``...
    Python keywords are avoided by the ``_`` suffix of a collision-free name.

    Args:
        name: Any text (a joint, link or robot name).
        taken: Identifiers already used; the result is added to it.
        prefix: Put in front (e.g. ``"q_"``).
    """
    import keyword

    base = prefix + re.sub(r"[^A-Za-z0-9_]+", "_", name.encode("ascii", "replace").decode("ascii"))
    if not base or base[0].isdigit():
        base = "x" + base
    if keyword.iskeyword(base) or base in ("np", "math", "sp"):
        base += "_"
    taken = set() if taken is None else taken
    candidate, count = base, 1
    while candidate in taken:
        count += 1
        candidate = f"{base}_{count}"
    taken.add(candidate)
    return candidate


def comment_text(text: str) -> str:
    """``text`` safe inside a Python docstring or a C ``/* */`` comment (see the module)."""
    return "".join(ch if _SAFE_COMMENT.fullmatch(ch) else _code_point(ch) for ch in text)


def terminal_text(text: str) -> str:
    """``text`` with every control or format character escaped (nothing moves the cursor,
    changes colours or starts a new line)."""

    def escape(ch: str) -> str:
        if ch.isprintable() and unicodedata.category(ch) not in ("Cf", "Zl", "Zp"):
            return ch
        return f"\\x{ord(ch):02x}" if ord(ch) < 0x100 else f"\\u{ord(ch):04x}"

    return "".join(escape(ch) for ch in text)


def latex_text(text: str) -> str:
    """``text`` for LaTeX's text mode (``\\text{...}``, ``\\texttt{...}``)."""
    out = []
    for ch in text:
        if ch in _LATEX_SPECIAL:
            out.append(_LATEX_SPECIAL[ch])
        elif " " <= ch <= "~":
            out.append(ch)
        else:
            out.append(_code_point(ch).replace("<", r"\textless{}").replace(">", r"\textgreater{}"))
    return "".join(out)


def json_text(value: object, **options) -> str:
    """``json.dumps`` with non-ASCII escaped (``options`` as for :func:`json.dumps`)."""
    return json.dumps(value, ensure_ascii=True, allow_nan=False, **options)
