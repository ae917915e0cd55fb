"""URDF validation: one strict reader in front of both Pinocchio and the reference.

:func:`parse_urdf` reads URDF text with a strict XML parser (no recovery, no DOCTYPE, no
entities, no network), checks the structure and the physics of the model, and returns a
small :class:`URDFSpec`. Every problem found is a :class:`Problem`; :func:`parse_urdf`
raises the first error as a :class:`~robodyn.exceptions.URDFError`, and :func:`lint_urdf`
returns them all, warnings included.

Conventions enforced here and relied on downstream:
    - joint axes are finite, non-zero and normalised to unit length;
    - ``<mimic>`` joints are honoured (``q_mimic = multiplier * q_source + offset``);
    - numbers follow one grammar (:func:`robodyn.urdf.xmltext.parse_number`); Pinocchio
      later reads only numbers robodyn wrote (:mod:`robodyn.urdf.normalised`);
    - masses are finite and non-negative; a moving link with positive mass has a
      positive semi-definite inertia (tolerance relative to the body's scale); breaking
      the triangle inequality is a loud warning (:class:`~robodyn.exceptions.RobodynWarning`),
      an error with ``strict=True``;
    - a ``<mimic>`` of a joint that does not exist is dropped with a loud warning;
    - a joint's ``<dynamics damping friction>`` (viscous damping b, Coulomb friction f) are
      finite and non-negative (0 where not given); on a fixed joint they have no effect
      (a warning ``lint`` shows);
    - a revolute or prismatic joint with ``lower > upper`` (Bullet's encoding of an
      unlimited joint, e.g. pybullet_data's cube_no_rotation.urdf) has no position limit,
      with a loud warning;
    - revolute limits that look written in degrees (±90, ±180, ±270, ±360, or beyond four
      turns) are kept as written, with a loud warning naming the values in radians.

The pieces live in :mod:`robodyn.urdf.xmltext` (XML and numbers), :mod:`robodyn.urdf.spec`
(the result types), :mod:`robodyn.urdf.urdf_reader` (reading each element),
:mod:`robodyn.urdf.tree_checks` (one tree, mimic relations) and
:mod:`robodyn.urdf.inertias` (mass properties).

This module does not import Pinocchio.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

from robodyn.common.text import printable
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.inertias import BODY_SCALE, TRIANGLE_TOLERANCE, check_inertias, check_moving_masses, moving_links
from robodyn.urdf.meshes import mesh_problems
from robodyn.urdf.spec import Inertial, JointSpec, Mimic, Problem, URDFSpec, child_index
from robodyn.urdf.tree_checks import MAX_DEPTH, check_mimics, check_tree
from robodyn.urdf.urdf_reader import KNOWN_JOINT_TYPES, MAX_MAGNITUDE, MOVING_JOINT_TYPES, Reader, read_inertial, read_joint
from robodyn.urdf.xmltext import MAX_XML_DEPTH, parse_number, parse_xml

#: The reader's old name (kept for code that patches it).
_Reader = Reader


def lint_urdf(
    text: str,
    source: str = "<string>",
    *,
    floating_base: bool = False,
    check_inertia: bool = True,
    strict: bool = False,
    base_dir: Path | None = None,
    package_dirs: Sequence[Path] = (),
) -> tuple[URDFSpec | None, list[Problem]]:
    """Check URDF text and return its spec (``None`` if it has errors) and every problem.

    Args:
        text: The URDF document.
        source: Where it came from, for messages.
        floating_base: Whether the root link moves freely (then every link moves).
        check_inertia: If false, physically impossible inertias of moving links are
            warnings instead of errors (some published URDFs have them).
        strict: Loud warnings (an inertia breaking the triangle inequality, a mimic of a
            joint that does not exist, ``lower > upper`` read as no limit) are errors.
        base_dir: Folder of the URDF file, for relative mesh paths.
        package_dirs: Folders under which ``package://`` mesh paths resolve.

    Returns:
        The validated spec, or ``None`` when any error was found, and the list of problems
        (errors and warnings) in document order.

    Raises:
        URDFError: Only if the text is not well-formed XML or not a ``<robot>`` document.
    """
    root = parse_xml(text, source)
    reader = Reader()
    links: dict[str, Inertial | None] = {}
    for index, node in enumerate(root.findall("link")):
        name = node.get("name")
        if not name:
            reader.error(f"link #{index + 1}", "has no name")
            continue
        if name in links:
            reader.error(f'link "{name}"', "is defined twice")
            continue
        inertial = node.find("inertial")
        links[name] = None if inertial is None else read_inertial(reader, f'link "{name}"', inertial)
    joints: dict[str, JointSpec] = {}
    for index, node in enumerate(root.findall("joint")):
        joint = read_joint(reader, node, index)
        if joint is None:
            continue
        if joint.name in joints:
            reader.error(f'joint "{joint.name}"', "is defined twice")
            continue
        joints[joint.name] = joint
    if not links:
        reader.error(None, "the robot has no links")
    tree_root = check_tree(reader, links, joints) if links else None
    check_mimics(reader, joints)
    for element, rule, severity in mesh_problems(root, base_dir=base_dir, package_dirs=package_dirs):
        (reader.error if severity == "error" else reader.warn)(element, rule)
    if tree_root is not None:
        children = child_index(joints)
        check_inertias(reader, links, moving_links(tree_root, children, floating_base), check_inertia, strict)
        check_moving_masses(reader, links, joints, children)
        if not floating_base and all(joint.type == "fixed" for joint in joints.values()):
            reader.error(None, "the robot has no moving joint (floating_base=True gives its root six degrees of freedom)")
    if strict:
        reader.problems = [Problem(problem.element, problem.rule) if problem.loud else problem for problem in reader.problems]
    errors = [problem for problem in reader.problems if problem.severity == "error"]
    spec = None if errors or tree_root is None else URDFSpec(root.get("name", "robot"), tree_root, links, joints, root)
    return spec, reader.problems


def parse_urdf(
    text: str,
    source: str = "<string>",
    *,
    floating_base: bool = False,
    check_inertia: bool = True,
    strict: bool = False,
    base_dir: Path | None = None,
    package_dirs: Sequence[Path] = (),
) -> URDFSpec:
    """Validate URDF text and return its spec (arguments as for :func:`lint_urdf`).

    Loud warnings are shown as :class:`~robodyn.exceptions.RobodynWarning` (one each).

    Raises:
        URDFError: Naming the source, the element and the rule of the first error found.
    """
    spec, problems = lint_urdf(
        text,
        source,
        floating_base=floating_base,
        check_inertia=check_inertia,
        strict=strict,
        base_dir=base_dir,
        package_dirs=package_dirs,
    )
    if spec is None:
        first = next(problem for problem in problems if problem.severity == "error")
        rule = first.rule
        if "inertia" in rule and check_inertia:
            rule += " (check_inertia=False loads it anyway)"
        raise URDFError(source, rule, first.element)
    for problem in problems:
        if problem.loud:
            warnings.warn(printable(f"{source}: {problem} (strict=True refuses it)"), RobodynWarning, stacklevel=3)
    return spec


__all__ = [
    "BODY_SCALE",
    "KNOWN_JOINT_TYPES",
    "MAX_DEPTH",
    "MAX_MAGNITUDE",
    "MAX_XML_DEPTH",
    "MOVING_JOINT_TYPES",
    "TRIANGLE_TOLERANCE",
    "Inertial",
    "JointSpec",
    "Mimic",
    "Problem",
    "URDFSpec",
    "lint_urdf",
    "parse_number",
    "parse_urdf",
    "parse_xml",
]
