"""Checks of a URDF's joints as a whole: one tree under one root, no chain deeper than
:data:`MAX_DEPTH`, mimic relations between two moving joints of one type.

Problems go to the :class:`~robodyn.urdf.urdf_reader.Reader` that read the elements. This
module does not import Pinocchio.
"""

from __future__ import annotations

from dataclasses import replace

from robodyn.urdf.spec import JointSpec, child_index
from robodyn.urdf.urdf_reader import Reader

#: Deepest kinematic chain accepted (Pinocchio's parser crashes around 4000).
MAX_DEPTH = 1000


def check_tree(reader: Reader, links: dict, joints: dict[str, JointSpec]) -> str | None:
    """Check that joints connect the links into one tree; return the root link.

    Args:
        reader: Collects the problems found.
        links: The links by name.
        joints: The joints by name.

    Returns:
        The root link's name, or ``None`` when the joints do not make one tree.
    """
    parent_of: dict[str, str] = {}
    for joint in joints.values():
        where = f'joint "{joint.name}"'
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in links:
                reader.error(where, f"its {role} link {link!r} does not exist")
        if joint.child in parent_of:
            reader.error(
                f'link "{joint.child}"',
                f"has two parent joints ({parent_of[joint.child]!r} and {joint.name!r}); a URDF must be a tree",
            )
        else:
            parent_of[joint.child] = joint.name
    if any(problem.severity == "error" for problem in reader.problems):
        return None
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        rule = (
            "no root link (the joints form a cycle)"
            if not roots
            else f"{len(roots)} root links {roots[:5]}; a URDF needs exactly one"
        )
        reader.error(None, rule)
        return None
    depth = {roots[0]: 0}
    stack = [roots[0]]
    children = child_index(joints)
    while stack:
        link = stack.pop()
        for joint in children.get(link, []):
            depth[joint.child] = depth[link] + 1
            if depth[joint.child] > MAX_DEPTH:
                reader.error(f'link "{joint.child}"', f"the kinematic chain is deeper than {MAX_DEPTH} links")
                return None
            stack.append(joint.child)
    unreached = [link for link in links if link not in depth]
    if unreached:
        reader.error(f'link "{unreached[0]}"', "is part of a cycle of joints, not of the tree under the root")
        return None
    return roots[0]


def check_mimics(reader: Reader, joints: dict[str, JointSpec]) -> None:
    """Check mimic relations; a mimic of a joint that does not exist is dropped (loud warning).

    Args:
        reader: Collects the problems found.
        joints: The joints by name; a dropped mimic is replaced in place.
    """
    for joint in list(joints.values()):
        if joint.mimic is None:
            continue
        where = f'joint "{joint.name}"'
        source = joints.get(joint.mimic.joint)
        if source is None:
            reader.warn(
                where,
                f"mimics joint {joint.mimic.joint!r}, which does not exist: it moves independently",
                loud=True,
            )
            joints[joint.name] = replace(joint, mimic=None)
        elif joint.type == "fixed":
            reader.warn(where, "is fixed, so its <mimic> has no effect")
        elif source.type == "fixed":
            reader.error(where, f"mimics the fixed joint {source.name!r}; a mimic relation needs two moving joints")
        elif source.mimic is not None:
            reader.error(where, f"mimics {source.name!r}, which is itself a mimic joint")
        elif source.type != joint.type:
            reader.error(where, f"a {joint.type} joint cannot mimic the {source.type} joint {source.name!r}")
