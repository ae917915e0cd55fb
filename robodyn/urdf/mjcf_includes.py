"""MJCF ``<include file>``: the included file's elements put where the ``<include>`` is,
as MuJoCo does, read through robodyn's file reader.

The rule: a file name is resolved, as MuJoCo 4 resolves it, against the main file's
folder, else against the including file's folder; it must lie inside the main file's
folder tree (``..`` and absolute paths out of it, also through a symlink, are refused);
each file is read through the reader given (regular files only, the size cap), the
included texts together are held to the same cap, a file is included once (MuJoCo
refuses a second time: this also refuses a cycle), at most :data:`MAX_INCLUDES` files,
and the tree they make together nests no deeper than
:data:`~robodyn.urdf.xmltext.MAX_XML_DEPTH`. Text given without a file has no folder:
its ``<include>`` is refused. This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from robodyn.common.text import printable
from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_state import Census
from robodyn.urdf.xmltext import MAX_XML_DEPTH, parse_xml

#: Most files one MJCF model includes (dm_control's suite files include three).
MAX_INCLUDES = 100


@dataclass
class _Including:
    """What the expansion of one model carries along."""

    label: str
    top: Path
    read_file: Callable[[Path], str]
    max_bytes: int
    census: Census
    seen: set[Path] = field(default_factory=set)
    size: int = 0


def expand_includes(
    root: ET.Element,
    *,
    label: str,
    path: Path | None,
    read_file: Callable[[Path], str] | None,
    max_bytes: int,
    census: Census,
) -> None:
    """Replace every ``<include file>`` of ``root`` by the elements of the file's
    ``<mujoco>``, in place (see the module for the rule).

    Args:
        root: The parsed ``<mujoco>`` element.
        label: The model's label, for messages.
        path: The model's file (``None``: text, which cannot include).
        read_file: Reads one file's text (regular files, the size cap), or ``None``.
        max_bytes: Most bytes of included text in all.
        census: Counts bodies and joints while each file is parsed.

    Raises:
        URDFError: One sentence naming the include that cannot be read.
    """
    if root.find(".//include") is None:
        return
    if path is None or read_file is None:
        raise URDFError(label, "an MJCF given as text cannot <include> files: load the file by its path")
    top = path.resolve().parent
    _expand(_Including(label, top, read_file, max_bytes, census), root, top, (False, False), 1)


def _expand(context: _Including, parent: ET.Element, here: Path, inside: tuple[bool, bool], depth: int) -> None:
    """Expand the includes below ``parent`` (``inside``: in ``<worldbody>``, in ``<default>``)."""
    if depth > MAX_XML_DEPTH:
        raise URDFError(context.label, f"the included MJCF files nest elements deeper than {MAX_XML_DEPTH} levels")
    index = 0
    while index < len(parent):
        child = parent[index]
        if child.tag != "include":
            within = (inside[0] or child.tag == "worldbody", inside[1] or child.tag == "default")
            _expand(context, child, here, within, depth + 1)
            index += 1
            continue
        included, folder = _load(context, child, here, inside)
        _expand(context, included, folder, inside, depth)
        parent[index : index + 1] = list(included)
        index += len(included)


def _load(context: _Including, node: ET.Element, here: Path, inside: tuple[bool, bool]) -> tuple[ET.Element, Path]:
    """The ``<mujoco>`` element of an included file, and the file's folder."""
    name = node.get("file")
    if not name:
        raise URDFError(context.label, "an MJCF <include> needs a file attribute")
    where = f"<include file={printable(name)!r}>"
    path = _resolve(context, name, here, where)
    if path in context.seen:
        raise URDFError(context.label, f"{where}: the file is already included (MuJoCo includes a file once)")
    if len(context.seen) >= MAX_INCLUDES:
        raise URDFError(context.label, f"{where}: more than {MAX_INCLUDES} included files")
    context.seen.add(path)
    text = context.read_file(path)
    context.size += len(text.encode("utf-8"))
    if context.size > context.max_bytes:
        raise URDFError(context.label, f"{where}: the included files are more than {context.max_bytes} bytes together")
    saved = (context.census.world, context.census.default)
    context.census.world, context.census.default = int(inside[0]), int(inside[1])
    try:
        included = parse_xml(text, str(path), root="mujoco", on_event=context.census)
    finally:
        context.census.world, context.census.default = saved
    return included, path.parent


def _resolve(context: _Including, name: str, here: Path, where: str) -> Path:
    """The included file: against the main file's folder, else the including file's;
    inside the main file's folder tree."""
    if "\x00" in name:
        raise URDFError(context.label, f"{where}: a file name cannot contain a NUL character")
    try:
        candidates = [(folder / name).resolve() for folder in dict.fromkeys((context.top, here))]
    except (OSError, RuntimeError) as error:  # a name too long for the file system, a symlink loop
        raise URDFError(context.label, f"{where}: the file name cannot be resolved ({error.__class__.__name__})") from None
    inside = [path for path in candidates if path.is_relative_to(context.top)]
    if not inside:
        raise URDFError(context.label, f"{where}: the file is outside the model's folder {printable(str(context.top))!r}")
    for path in inside:
        try:
            if path.exists():
                return path
        except OSError:
            continue
    return inside[0]
