"""Constraints written in a file: a small YAML document of anchors, welds and contacts.

A URDF describes a tree and cannot close a loop; a user gives the loop (and welds and
contacts) in a YAML file next to it: three lists, one entry a constraint, whose keys are
the fields of the constraint's value (:mod:`robodyn.constraints.values`)::

    anchor:                    # PointAnchor: a point of one link held on a point of another
      - name: loop
        frame1: coupler
        point1: [0.35, 0, 0]   # [m], in frame1's frame
        frame2: rocker         # left out: the world
        point2: [0.3, 0, 0]    # left out: where point1 is at the neutral configuration
    weld:                      # FrameAnchor: origin1 = [x, y, z, roll, pitch, yaw] in [m], [rad]
      - frame1: gripper
        origin1: [0, 0, 0.1, 0, 0, 0]
    contact:                   # PointContact (bilateral while active; friction 0: sliding)
      - frame: foot
        point: [0, 0, -0.02]
        normal: [0, 0, 1]
        friction: 0.8
        plane_point: [0, 0, 0]

YAML because its parser (PyYAML, which xacro needs) is already a dependency on every
Python robodyn supports, and ROS users write it. :func:`read_constraints` reads it (a path,
or the text itself) into constraint values (anchors, then welds, then contacts, each in the
file's order). Anything else is refused in one :class:`~robodyn.exceptions.InputError`
naming the list, entry and key: a file that is not YAML (or uses aliases, or gives a key twice), an unknown list
or key (nothing in the file is silently ignored), a coordinate that is not a finite number
within :data:`MAX_COORDINATE`, more than :data:`MAX_CONSTRAINTS` entries.
Link names are checked against the robot when the constraints are bound to it
(:func:`robodyn.load`), in one line listing its links.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

import yaml

from robodyn.common.text import printable, quoted
from robodyn.constraints.values import Constraint, FrameAnchor, PointAnchor, PointContact
from robodyn.exceptions import InputError

#: Largest constraints file read, in bytes.
MAX_FILE_BYTES = 1_000_000
#: Most constraints a file may list.
MAX_CONSTRAINTS = 1000
#: Largest coordinate accepted, in [m] (and [rad] for angles): a robot is not kilometres wide.
MAX_COORDINATE = 1e6

#: List name -> the constraint it builds and the keys it takes (the value's fields).
TABLES: dict[str, tuple[type, tuple[str, ...]]] = {
    "anchor": (PointAnchor, ("name", "frame1", "point1", "frame2", "point2")),
    "weld": (FrameAnchor, ("name", "frame1", "origin1", "frame2", "origin2")),
    "contact": (PointContact, ("name", "frame", "point", "normal", "friction", "plane_point")),
}
#: The keys holding names (strings); every other key holds numbers.
_NAMES = ("name", "frame1", "frame2", "frame")
#: What the refusals say the file must be.
_EXPECTED = "a YAML file of anchor, weld and contact lists (docs/constraints.md)"


class _Loader(yaml.SafeLoader):
    """YAML's safe loader (plain data only), refusing aliases (``*name``: no expansion bombs)
    and a key given twice in one mapping."""

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            raise yaml.YAMLError("aliases (*name) are not accepted")
        return super().compose_node(parent, index)

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        """A mapping, refusing a key given twice (YAML would keep the last, silently dropping the first)."""
        mapping = super().construct_mapping(node, deep=deep)
        if len(mapping) < len(node.value):
            seen: set[Any] = set()
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"the key {printable(repr(key))[:40]} is given twice", key_node.start_mark
                    )
                seen.add(key)
        return mapping


# YAML 1.2's floats (1e-3, 2E+1), which YAML 1.1's resolver reads as strings
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$"), list("-+0123456789.")
)


def _is_text(source: str) -> bool:
    """Whether a string is YAML text rather than a path: no such file, and a newline in it."""
    if "\n" not in source:
        return False
    try:
        return not Path(source).is_file()
    except (OSError, ValueError):  # a name too long or with a NUL byte is no file
        return True


def _text(source: str | os.PathLike) -> tuple[str, str]:
    """``(label, text)`` of a path or of YAML text given as such."""
    if isinstance(source, str) and _is_text(source):
        if len(source) > MAX_FILE_BYTES:
            raise InputError("constraints", f"text of at most {MAX_FILE_BYTES} characters", f"{len(source)} characters")
        return "<text>", source
    if not isinstance(source, (str, os.PathLike)):
        raise InputError("constraints", "a path or YAML text", printable(repr(source))[:80])
    path = Path(source)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError("constraints", f"a file of at most {MAX_FILE_BYTES} bytes", f"{quoted(str(path))}: {size} bytes")
        return printable(str(path))[:200], path.read_text(encoding="utf-8")
    except InputError:
        raise
    except UnicodeDecodeError:
        raise InputError("constraints", f"{_EXPECTED} in UTF-8", f"{quoted(str(path))}: not UTF-8 text") from None
    except (OSError, ValueError) as error:
        reason = getattr(error, "strerror", None) or "unreadable"
        raise InputError("constraints", _EXPECTED, f"{quoted(str(path))}: {reason}") from None


def _number(value: Any, where: str) -> float:
    """A finite number within :data:`MAX_COORDINATE` (a huge integer is refused too)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(where, "a number", printable(repr(value))[:80])
    if isinstance(value, int) and abs(value) > MAX_COORDINATE:
        raise InputError(where, f"a number within ±{MAX_COORDINATE:g}", f"{str(value)[:40]}")
    number = float(value)
    if not math.isfinite(number) or abs(number) > MAX_COORDINATE:
        raise InputError(where, f"a finite number within ±{MAX_COORDINATE:g}", repr(number))
    return number


def _value(key: str, value: Any, where: str) -> Any:
    """A key's value checked: a name (a string) or numbers (a number or an array of them)."""
    if key in _NAMES:
        if not isinstance(value, str):
            raise InputError(where, "a string (a link name)" if key != "name" else "a string", printable(repr(value))[:80])
        return value
    if isinstance(value, list):
        return tuple(_number(item, f"{where}[{index}]") for index, item in enumerate(value))
    return _number(value, where)


def _entry(table: str, index: int, entry: Any) -> Constraint:
    """One entry of a list as its constraint (every key known and checked)."""
    kind, keys = TABLES[table]
    where = f"{table}[{index}]"
    if not isinstance(entry, dict):
        raise InputError(where, f"a mapping of the keys {', '.join(keys)}", printable(repr(entry))[:80])
    unknown = sorted(str(key) for key in entry if key not in keys)
    if unknown:
        raise InputError(f"{where}.{printable(unknown[0])[:40]}", f"one of the keys {', '.join(keys)}", "an unknown key")
    required = keys[1]
    if required not in entry:
        raise InputError(f"{where}.{required}", "given (a link name)", "nothing")
    fields = {key: _value(key, value, f"{where}.{key}") for key, value in entry.items()}
    try:
        return kind(**fields)  # type: ignore[no-any-return, unused-ignore]
    except InputError as error:  # the value's own checks (sizes, a zero normal), named where in the file
        raise InputError(f"{where}.{error.argument}", error.expected, error.received) from None


def read_constraints(source: str | os.PathLike) -> tuple[Constraint, ...]:
    """The constraints of a YAML constraints file (see the module for its lists and keys).

    Args:
        source: A path to the file, or its text (a string holding a newline).

    Returns:
        The constraints: anchors, then welds, then contacts, each in the file's order.

    Raises:
        InputError: For a file that cannot be read or is not YAML, an unknown list or
            key, a missing link name, a value that is not a finite number within
            :data:`MAX_COORDINATE` (or of the wrong size), or more than
            :data:`MAX_CONSTRAINTS` constraints; the message names the list, entry and key.
    """
    label, text = _text(source)
    try:
        document = yaml.load(text, Loader=_Loader)
    except (yaml.YAMLError, RecursionError, ValueError) as error:
        reason = " ".join(str(error).split())[:160]
        raise InputError("constraints", _EXPECTED, f"{quoted(label)}: {printable(reason)}") from None
    document = {} if document is None else document
    if not isinstance(document, dict):
        raise InputError("constraints", _EXPECTED, f"{quoted(label)}: {type(document).__name__}")
    unknown = sorted(str(key) for key in document if key not in TABLES)
    if unknown:
        raise InputError("constraints", _EXPECTED, f"{quoted(label)}: an unknown list {quoted(unknown[0][:40])}")
    constraints: list[Constraint] = []
    for table in TABLES:
        entries = document.get(table)
        entries = [] if entries is None else entries  # `anchor:` left empty; `anchor: 0` is refused
        if not isinstance(entries, list):
            raise InputError(table, f"a list of {table} entries (each a '- ' item)", f"{quoted(label)}: {type(entries).__name__}")
        if len(constraints) + len(entries) > MAX_CONSTRAINTS:
            raise InputError("constraints", f"at most {MAX_CONSTRAINTS} constraints", f"{quoted(label)}: more")
        constraints += [_entry(table, index, entry) for index, entry in enumerate(entries)]
    if not constraints:
        raise InputError("constraints", _EXPECTED, f"{quoted(label)}: no constraint")
    return tuple(constraints)


__all__ = ["MAX_CONSTRAINTS", "MAX_COORDINATE", "MAX_FILE_BYTES", "TABLES", "read_constraints"]
