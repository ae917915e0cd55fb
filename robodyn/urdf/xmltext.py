"""Reading URDF text: the strict XML parser and the one number grammar.

This module does not import Pinocchio.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import cast

from robodyn.exceptions import URDFError

#: Deepest nesting of XML elements accepted (a URDF needs 5; xacro output about 10).
MAX_XML_DEPTH = 100

_FORBIDDEN_XML = re.compile(r"<!DOCTYPE|<!ENTITY", re.IGNORECASE)


def parse_xml(
    text: str, source: str, *, root: str = "robot", on_event: Callable[[str, ET.Element], None] | None = None
) -> ET.Element:
    """Parse URDF text strictly and return its ``<robot>`` element (``root``: the
    root element expected instead, e.g. MJCF's ``"mujoco"``).

    Whitespace (and a byte-order mark) before the XML declaration is accepted, as urdfdom
    does. Elements nested deeper than :data:`MAX_XML_DEPTH` are refused while parsing
    (the parser never recurses, nor does anything downstream get such a tree).
    ``on_event`` is called with each ``"start"`` / ``"end"`` event and its element while
    parsing (the element's attributes are read at its start): a reader counts there, and
    refuses by raising, before the whole tree is built.

    Args:
        text: The XML text.
        source: The file or robot name, for the error.
        root: The root element expected.
        on_event: Called as ``on_event(event, element)`` while parsing (``None``: not called).

    Raises:
        URDFError: If the text is not well-formed XML, declares a DOCTYPE or entities,
            nests elements too deeply, or its root element is not ``<robot>``.
    """
    if _FORBIDDEN_XML.search(text):
        raise URDFError(source, "DOCTYPE and entity declarations are not allowed in a URDF")
    text = text.lstrip(" \t\r\n\ufeff")
    parser: ET.XMLPullParser[ET.Element] = ET.XMLPullParser(events=("start", "end"))
    depth = 0
    top: ET.Element | None = None
    try:
        for start in range(0, max(len(text), 1), 1 << 16):
            parser.feed(text[start : start + (1 << 16)])
            for item in parser.read_events():
                # only "start"/"end" events were asked for: each is an (event, Element) pair
                event, element = cast("tuple[str, ET.Element]", item)
                depth += 1 if event == "start" else -1
                if on_event is not None:
                    on_event(event, element)
                top = element if top is None else top
                if depth > MAX_XML_DEPTH:
                    raise URDFError(source, f"XML elements are nested deeper than {MAX_XML_DEPTH} levels (<{element.tag}>)")
        parser.close()
    except ET.ParseError as error:
        raise URDFError(source, f"not well-formed XML ({error})") from None
    assert top is not None  # parser.close() refuses a document without an element
    if top.tag != root:
        raise URDFError(source, f"the root element must be <{root}>, not <{top.tag}>")
    return top


#: The number grammar of a URDF attribute, the only one robodyn accepts: an optional sign,
#: ASCII decimal digits with an optional fraction and exponent, or ``inf`` / ``infinity``
#: (any case; refused later wherever a finite value is needed) and ``nan`` (always
#: refused), after stripping ASCII whitespace. No underscores, no other scripts' digits, no
#: hexadecimal: what Python's ``float`` would also accept but a C++ URDF parser would read
#: differently is refused, and Pinocchio only ever reads numbers robodyn wrote.
_NUMBER = re.compile(r"[+-]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)", re.IGNORECASE)
_ASCII_SPACE = " \t\n\r"


def parse_number(text: str) -> float | None:
    """The value of one number in URDF text, or ``None`` if it is not in the grammar.

    Args:
        text: The attribute text (surrounding ASCII whitespace allowed).

    Returns:
        The float (``inf`` and ``nan`` included, for the caller to refuse), or ``None``.
    """
    token = text.strip(_ASCII_SPACE)
    return float(token) if _NUMBER.fullmatch(token) else None


def split_numbers(text: str) -> list[str]:
    """Tokens of a list of numbers separated by ASCII whitespace.

    Args:
        text: The attribute's text.
    """
    return [token for token in re.split("[ \t\n\r]+", text.strip(_ASCII_SPACE)) if token]
