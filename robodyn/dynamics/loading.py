"""``robodyn.load``: the one door from a URDF (path, text, zoo or generated name) to a Robot.

The URDF is validated first (:mod:`robodyn.urdf.validation`); Pinocchio then builds the model
from a normalised copy of it:

- continuous joints become revolute joints with unbounded limits, so that ``q`` holds
  their angle (one number a degree of freedom) instead of Pinocchio's (cos, sin) pair;
- joint axes are written with unit length (both Pinocchio and the reference read the same
  axis);
- ``<mimic>`` is honoured (Pinocchio's ``mimic=True``); a mimic tag on a fixed joint,
  which cannot move, is dropped (the validator warns about it).
"""

from __future__ import annotations

import contextlib
import copy
import os
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import replace

import pinocchio as pin

from robodyn.common.inputs import as_state
from robodyn.dynamics.mimic import has_mimic, mimic_expansion
from robodyn.dynamics.robot import LoadOptions, Robot
from robodyn.exceptions import URDFError
from robodyn.urdf.sources import URDFSource, locked_source, resolve_source
from robodyn.urdf.validation import URDFSpec, parse_urdf

#: Limit written for continuous joints in the copy Pinocchio reads, in [rad].
_UNBOUNDED = "1e10"


def pinocchio_xml(spec: URDFSpec) -> str:
    """The URDF text Pinocchio builds the model from (see the module docstring)."""
    root = copy.deepcopy(spec.xml)
    for node in root.findall("joint"):
        joint = spec.joints[node.get("name")]
        if joint.type == "fixed":
            for mimic in node.findall("mimic"):
                node.remove(mimic)
            continue
        axis = node.find("axis")
        if axis is None:
            axis = ET.SubElement(node, "axis")
        axis.set("xyz", " ".join(repr(float(value)) for value in joint.axis))
        if joint.type == "continuous":
            node.set("type", "revolute")
            limit = node.find("limit")
            if limit is None:
                limit = ET.SubElement(node, "limit", effort="0", velocity="0")
            limit.set("lower", "-" + _UNBOUNDED)
            limit.set("upper", _UNBOUNDED)
    return ET.tostring(root, encoding="unicode")


def load(
    source: str | os.PathLike,
    *,
    floating_base: bool | None = None,
    gravity: Sequence[float] | None = None,
    check_inertia: bool = True,
    lock: dict[str, float] | None = None,
    threads: int | None = None,
) -> Robot:
    """Load a robot.

    Args:
        source: A URDF file path, URDF XML text, a zoo robot name (``"panda"``,
            ``"ur5"``, ...) or a generated robot's name (``"rp_arm"``); ``robodyn list``
            prints the names.
        floating_base: Give the root link a free-flyer joint. ``None``: true for zoo
            robots that walk, swim or fly, false otherwise.
        gravity: Gravity acceleration in the world frame, in [m/s²]; default
            ``(0, 0, -9.81)``.
        check_inertia: Refuse physically impossible inertias on moving links (set false
            to load published models that have them).
        lock: Joints to freeze, by name, at positions in [rad] / [m] (e.g. a gripper's
            fingers): they become fixed joints, and joints mimicking them follow.
        threads: Native threads for batches of states; default every available core.

    Returns:
        The robot.

    Raises:
        UnknownRobotError: If the name is not a file or known robot.
        URDFError: If the URDF cannot be read or describes an impossible robot.
        InputError: If ``gravity`` is not 3 finite numbers.
    """
    resolved = resolve_source(source)
    if lock:
        resolved = locked_source(resolved, lock, floating_base=floating_base, check_inertia=check_inertia)
    return build_robot(resolved, floating_base=floating_base, gravity=gravity, check_inertia=check_inertia, threads=threads)


def rebuild(robot: Robot, *, urdf: str | None = None, label: str | None = None) -> Robot:
    """A new robot from ``robot``'s source and options: an independent copy, or (with
    ``urdf``) the same robot edited (a payload welded on, ...), named ``label``."""
    source = (
        robot.source
        if urdf is None
        else replace(robot.source, text=urdf, label=label or robot.source.label, name=label or robot.name)
    )
    options = robot.options
    return build_robot(
        source,
        floating_base=options.floating_base,
        gravity=options.gravity,
        check_inertia=options.check_inertia,
        threads=options.threads,
    )


def build_robot(
    resolved: URDFSource,
    *,
    floating_base: bool | None = None,
    gravity: Sequence[float] | None = None,
    check_inertia: bool = True,
    threads: int | None = None,
) -> Robot:
    """Build a robot from a resolved URDF source (what :func:`load` does after resolving).

    Arguments as for :func:`load`.
    """
    floating = resolved.floating_base if floating_base is None else bool(floating_base)
    spec = parse_urdf(resolved.text, resolved.label, floating_base=floating, check_inertia=check_inertia, **resolved.mesh_context)
    xml = pinocchio_xml(spec)
    with _captured_stderr() as captured:
        try:
            if floating:
                model = pin.buildModelFromXML(xml, pin.JointModelFreeFlyer(), "root_joint", mimic=True)
            else:
                model = pin.buildModelFromXML(xml, mimic=True)
        except (RuntimeError, ValueError) as error:
            model, refusal = None, str(error).strip()
    if model is None:
        reason = " ".join(line.strip() for line in captured.text().splitlines() if line.strip())
        raise URDFError(resolved.label, f"Pinocchio refused the model ({refusal}{'; ' + reason if reason else ''})")
    mimic = mimic_expansion(model, spec, xml, floating) if has_mimic(model, spec, floating) else None
    if gravity is not None:
        model.gravity.linear = as_state(gravity, "gravity", 3)
    if mimic is not None:
        mimic.model.gravity.linear = model.gravity.linear
    if model.nv == 0:
        raise URDFError(resolved.label, "the robot has no moving joint")
    name = spec.name if resolved.name == "robot" else resolved.name
    options = LoadOptions(floating, tuple(float(g) for g in model.gravity.linear), check_inertia, threads)  # type: ignore[arg-type]
    return Robot(model, spec=spec, source=resolved, options=options, name=name, mimic=mimic)


class _Captured:
    """What was written to stderr, read when the capture ends."""

    def __init__(self) -> None:
        self.content = ""

    def text(self) -> str:
        return self.content


@contextlib.contextmanager
def _captured_stderr():
    """Capture what C++ code writes to the process's stderr (file descriptor 2).

    Pinocchio's URDF parser prints its reason for refusing a model there, where Python
    cannot catch it; robodyn puts it into the error message instead.
    """
    with tempfile.TemporaryFile() as stream:
        sys.stderr.flush()
        saved = os.dup(2)
        captured = _Captured()
        try:
            os.dup2(stream.fileno(), 2)
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            stream.seek(0)
            captured.content = stream.read(4000).decode("utf-8", "replace")


__all__ = ["build_robot", "load", "pinocchio_xml", "rebuild"]
