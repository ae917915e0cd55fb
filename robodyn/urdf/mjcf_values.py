"""Numbers, directions and poses of an MJCF file, read as MuJoCo's compiler reads them.

Orientations ``quat`` (**w x y z**), ``axisangle``, ``euler`` (``<compiler eulerseq>``:
lower case axes move with the frame, upper case are fixed), ``xyaxes`` and ``zaxis``;
angles in degrees unless ``<compiler angle="radian">``. This module does not import
Pinocchio or MuJoCo.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.common.rotations import axis_rotation, matrix_rpy
from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_state import MjcfRobot
from robodyn.urdf.xmltext import parse_number, split_numbers

#: The attributes that orient an element.
ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


def number(label: str, where: str, text: str) -> float:
    """One finite number.

    Args:
        label: The file's name, for the error.
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        text: The number's text.

    Raises:
        URDFError: If ``text`` is not one, naming ``where``.
    """
    value = parse_number(text)
    if value is None or not math.isfinite(value):
        raise URDFError(label, f"{where}: {text!r} is not a finite number")
    return value


def keyword(label: str, where: str, attribute: str, text: str, allowed: tuple[str, ...]) -> str:
    """A keyword spelled as MuJoCo spells it (case matters: ``"True"`` is not ``"true"``).

    Args:
        label: The file's name, for the error.
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        attribute: The attribute's name.
        text: The attribute's value.
        allowed: The keywords MuJoCo accepts there.

    Raises:
        URDFError: If ``text`` is not one of ``allowed``, naming the attribute.
    """
    if text not in allowed:
        raise URDFError(label, f"{where}: {attribute}={text!r} must be one of {', '.join(allowed)} (as MuJoCo spells them)")
    return text


#: MuJoCo's boolean keywords, and those with ``auto``.
BOOLEAN = ("true", "false")
AUTO = ("true", "false", "auto")


def floats(label: str, where: str, text: str, count: int) -> np.ndarray:
    """Exactly ``count`` finite numbers, shape (count,).

    Args:
        label: The file's name, for the error.
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        text: The attribute's text, numbers separated by whitespace.
        count: How many numbers it must hold.

    Raises:
        URDFError: If there are more, fewer, or one is not a finite number.
    """
    tokens = split_numbers(text)
    if len(tokens) != count:
        raise URDFError(label, f"{where}: {text!r} must be {count} numbers")
    return np.array([number(label, where, token) for token in tokens])


def angle(robot: MjcfRobot, value: float) -> float:
    """An angle of the file in [rad] (``<compiler angle>``).

    Args:
        robot: The MJCF robot being read (its compiler settings and file name).
        value: The angle as the file writes it: in [deg] under ``<compiler angle="degree">`` (MuJoCo's default), else [rad].
    """
    return math.radians(value) if robot.compiler.degree else value


def orientation(robot: MjcfRobot, where: str, attributes: dict[str, str]) -> np.ndarray:
    """The rotation matrix an element's orientation attribute gives (identity if none).

    Args:
        robot: The MJCF robot being read (its compiler settings and file name).
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        attributes: The element's attributes (at most one of ``quat``, ``axisangle``, ``euler``, ``xyaxes``, ``zaxis``).
    """
    given = [key for key in ORIENTATIONS if key in attributes]
    if len(given) > 1:
        raise URDFError(robot.label, f"{where}: more than one orientation ({', '.join(given)})")
    if not given:
        return np.eye(3)
    key, text = given[0], attributes[given[0]]
    if key == "quat":
        w, x, y, z = floats(robot.label, where, text, 4)
        return quaternion_matrix(robot.label, where, np.array([w, x, y, z]))
    if key == "axisangle":
        values = floats(robot.label, where, text, 4)
        return axis_rotation(unit(robot.label, where, values[:3]), angle(robot, values[3]))
    if key == "euler":
        return _euler(robot, floats(robot.label, where, text, 3))
    if key == "xyaxes":
        values = floats(robot.label, where, text, 6)
        x = unit(robot.label, where, values[:3])
        y = unit(robot.label, where, values[3:] - values[3:] @ x * x)
        return np.column_stack([x, y, np.cross(x, y)])
    return zaxis(unit(robot.label, where, floats(robot.label, where, text, 3)))


def quaternion_matrix(label: str, where: str, wxyz: np.ndarray) -> np.ndarray:
    """The rotation of a quaternion in MuJoCo's order (w, x, y, z), normalised.

    Args:
        label: The file's name, for the error.
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        wxyz: The quaternion ``(w, x, y, z)``, shape (4,), not zero.
    """
    norm = float(np.linalg.norm(wxyz))
    if norm < 1e-12:
        raise URDFError(label, f"{where}: the quaternion must not be zero")
    w, x, y, z = wxyz / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_quaternion(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion **x, y, z, w** (robodyn's order, ``w >= 0``) of a rotation.

    Args:
        rotation: A rotation matrix, shape (3, 3).
    """
    trace = float(np.trace(rotation))
    if trace > 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        w, x, y, z = (
            s / 4,
            (rotation[2, 1] - rotation[1, 2]) / s,
            (rotation[0, 2] - rotation[2, 0]) / s,
            (rotation[1, 0] - rotation[0, 1]) / s,
        )
    else:
        i = int(np.argmax(np.diag(rotation)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(max(1.0 + rotation[i, i] - rotation[j, j] - rotation[k, k], 0.0))
        vector = np.empty(3)
        vector[i], vector[j], vector[k] = s / 4, (rotation[j, i] + rotation[i, j]) / s, (rotation[k, i] + rotation[i, k]) / s
        w, (x, y, z) = (rotation[k, j] - rotation[j, k]) / s, vector
    quaternion = np.array([x, y, z, w])
    quaternion /= np.linalg.norm(quaternion)
    return -quaternion if quaternion[3] < 0 else quaternion


def _euler(robot: MjcfRobot, angles: np.ndarray) -> np.ndarray:
    rotation = np.eye(3)
    for axis_name, value in zip(robot.compiler.eulerseq, angles, strict=True):
        axis = np.eye(3)["xyz".index(axis_name.lower())]
        turn = axis_rotation(axis, angle(robot, float(value)))
        rotation = rotation @ turn if axis_name.islower() else turn @ rotation
    return rotation


def zaxis(z: np.ndarray) -> np.ndarray:
    """The smallest rotation taking (0, 0, 1) to ``z``, as MuJoCo's ``zaxis``.

    Args:
        z: The unit direction, shape (3,).
    """
    cross = np.cross([0.0, 0.0, 1.0], z)
    sine, cosine = float(np.linalg.norm(cross)), float(z[2])
    if sine < 1e-14:
        return np.eye(3) if cosine > 0 else axis_rotation(np.array([1.0, 0.0, 0.0]), math.pi)
    return axis_rotation(cross / sine, math.atan2(sine, cosine))


def unit(label: str, where: str, vector: np.ndarray) -> np.ndarray:
    """``vector`` normalised.

    Args:
        label: The file's name, for the error.
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        vector: The direction, shape (3,).

    Raises:
        URDFError: If it is zero.
    """
    norm = float(np.linalg.norm(vector))
    if norm < 1e-12:
        raise URDFError(label, f"{where}: a direction must not be zero")
    return vector / norm


def pose(robot: MjcfRobot, where: str, attributes: dict[str, str]) -> np.ndarray:
    """The 4×4 pose of an element's ``pos`` and orientation in its body's frame.

    Args:
        robot: The MJCF robot being read (its compiler settings and file name).
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        attributes: The element's attributes (``pos`` in [m] and an orientation).
    """
    result = np.eye(4)
    result[:3, :3] = orientation(robot, where, attributes)
    result[:3, 3] = floats(robot.label, where, attributes.get("pos", "0 0 0"), 3)
    return result


def translation(vector: np.ndarray) -> np.ndarray:
    """The 4×4 pose of a pure translation by ``vector`` (3,) in [m].

    Args:
        vector: The translation, shape (3,), in [m].
    """
    result = np.eye(4)
    result[:3, 3] = vector
    return result


def fromto_pose(robot: MjcfRobot, where: str, text: str) -> tuple[np.ndarray, float]:
    """A ``fromto``'s pose (centre; z along the segment, from its second point to its first,
    as MuJoCo turns it) and half-length.

    Args:
        robot: The MJCF robot being read (its compiler settings and file name).
        where: Where in the file the value is (e.g. ``'joint "elbow"'``), for the error.
        text: The ``fromto`` attribute: the segment's two end points, 6 numbers in [m].
    """
    ends = floats(robot.label, where, text, 6)
    result = np.eye(4)
    result[:3, 3] = (ends[:3] + ends[3:]) / 2
    length = float(np.linalg.norm(ends[3:] - ends[:3]))
    if length > 1e-12:
        result[:3, :3] = zaxis((ends[:3] - ends[3:]) / length)
    return result, length / 2


def write_origin(parent: ET.Element, placement: np.ndarray) -> None:
    """A URDF ``<origin>`` of a 4×4 pose under ``parent``.

    Args:
        parent: The URDF element (a ``<joint>``, ``<inertial>``, ``<visual>``, ...).
        placement: The pose, shape (4, 4), translation in [m].
    """
    ET.SubElement(parent, "origin", xyz=text(placement[:3, 3]), rpy=text(matrix_rpy(placement[:3, :3])))


def text(values: np.ndarray) -> str:
    """Numbers as URDF text, every digit kept.

    Args:
        values: The numbers, shape (n,).
    """
    return " ".join(repr(float(value)) for value in values)
