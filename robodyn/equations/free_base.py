"""A floating base for the symbolic programs: the tree with the free base as body 0, and the
base's input symbols (Pinocchio's free flyer: quaternion, body-frame velocity and
acceleration).

:func:`floating_tree` and :func:`floating_reference` renumber a floating tree (six virtual
joints) so that body 0 is the free base; :class:`BaseSymbols` are that body's inputs. Used by
:func:`robodyn.equations.newton_euler.free_base_newton_euler` and the compact equations
(``free_base=True``). No Pinocchio here.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import sympy as sp

from robodyn.exceptions import InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.tree import KinematicTree


def floating_tree(tree: KinematicTree) -> KinematicTree:
    """A floating tree (six virtual joints) as a tree whose body 0 is the free base.

    Body 0 is the root link (no joint: zero axis, identity origin, parent -1), the moving
    joints' bodies follow with their parents renumbered, armature rotors stay roots; the
    selection and offset keep the independent joints' columns (body 0's row is zero).
    The programs take body 0's motion as inputs (``free_base=True`` of
    :func:`derive_newton_euler` and :func:`robodyn.equations.compact.derive_compact`).

    Args:
        tree: A floating-base tree.

    Raises:
        InputError: For a fixed-base tree.
    """
    if not tree.floating_base:
        raise InputError("tree", "a floating-base tree (floating_base=True)", f"the fixed-base {tree.name}")
    root = tree.bodies[5]
    base = replace(root, parent=-1, axis=np.zeros(3), revolute=False, origin=np.eye(4))
    moved = [replace(body, parent=body.parent - 5 if body.parent >= 5 else -1) for body in tree.bodies[6:]]
    keep = [5, *range(6, len(tree.bodies))]
    return KinematicTree(
        tree.name,
        [base, *moved],
        list(tree.joint_names[6:]),
        tree.selection[keep][:, 6:],
        tree.offset[keep],
        tree.ancestors[np.ix_(keep, keep)],
        floating_base=False,
    )


def floating_reference(robot: ReferenceRobot) -> ReferenceRobot:
    """A floating reference robot with its tree as :func:`floating_tree` (for ``free_base=True``).

    Args:
        robot: A floating-base reference robot.
    """
    tree = floating_tree(robot.tree)
    return ReferenceRobot(tree, name=robot.name, urdf=robot.urdf, spec=robot.spec, gravity=robot.gravity_vector)


@dataclass(frozen=True)
class BaseSymbols:
    """The free base's inputs of a program (Pinocchio's free flyer).

    Attributes:
        quaternion: ``x, y, z, w`` of the base's orientation (``q[3:7]``).
        velocity: Linear then angular velocity of the base in its own frame (``v[0:6]``).
        acceleration: Pinocchio's ``v̇[0:6]``: the spatial acceleration in the base frame
            (the base origin's classical acceleration is ``a_lin + ω × v_lin``).
    """

    quaternion: tuple[sp.Symbol, ...]
    velocity: tuple[sp.Symbol, ...]
    acceleration: tuple[sp.Symbol, ...]

    @classmethod
    def make(cls) -> BaseSymbols:
        """Fresh symbols (``Dummy``: never equal to a joint's symbol, whatever its name)."""

        def dummies(names: str) -> tuple[sp.Symbol, ...]:
            return tuple(sp.Dummy(name, real=True) for name in names.split())

        return cls(dummies("qx qy qz qw"), dummies("vx vy vz wx wy wz"), dummies("ax ay az bx by bz"))

    def gravity(self, gravity: sp.Matrix) -> sp.Matrix:
        """``Rᵀ g``: world gravity in the base frame, ``R`` of the quaternion (Eigen's formula).

        Args:
            gravity: World gravity, 3×1, in [m/s²].
        """
        x, y, z, w = self.quaternion
        R = sp.Matrix(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        return R.T * gravity
