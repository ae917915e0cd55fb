"""The terms of ``tau = M(q) a + C(q, v) v + G(q)`` at one state, with their JSON and text.

:func:`dynamics_terms` evaluates them (Pinocchio through :class:`~robodyn.dynamics.robot.Robot`);
:class:`DynamicsTerms` carries them with the per-degree-of-freedom records
(``robot.dofs``) that name and give units to each entry. Used by ``robodyn equations``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.robot import Robot

#: The equation the terms make up.
EQUATION = "tau = M(q) a + C(q, v) v + G(q)"


@dataclass(frozen=True)
class DynamicsTerms:
    """The terms of ``tau = M(q) a + C(q, v) v + G(q)`` at one state (SI units).

    Attributes:
        robot: The robot's name.
        joint_names: Its joints (the root joint first on a floating base).
        dofs: One record a velocity coordinate (names, units), length nv.
        q: Configuration, shape (nq,); ``v``, ``a``: velocity and acceleration, (nv,).
        tau: Joint torques (N m) or forces (N), shape (nv,).
        M: Mass matrix, shape (nv, nv). ``C``: Coriolis matrix, (nv, nv).
        G: Generalised gravity, shape (nv,).
    """

    robot: str
    joint_names: tuple[str, ...]
    dofs: tuple[Dof, ...]
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    M: np.ndarray
    C: np.ndarray
    G: np.ndarray

    def units(self) -> dict[str, list[str]]:
        """Units of each entry of ``v``, ``a`` and ``tau``, by velocity coordinate."""
        return {quantity: [dof.unit(quantity) for dof in self.dofs] for quantity in ("v", "a", "tau")}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (the ``robodyn equations --json`` output): terms and their units."""
        return {
            "robot": self.robot,
            "joint_names": list(self.joint_names),
            "equation": EQUATION,
            "units": {**self.units(), "M": "SI (kg m^2, kg m or kg by joint pair)", "C": "SI (M per second)"},
            "q": self.q.tolist(),
            "v": self.v.tolist(),
            "a": self.a.tolist(),
            "tau": self.tau.tolist(),
            "M": self.M.tolist(),
            "C": self.C.tolist(),
            "G": self.G.tolist(),
        }

    def text(self, *, precision: int = 6) -> str:
        """Readable text, one block a term, with units (``precision`` significant digits).

        Args:
            precision: Significant digits of each number.
        """
        lines = [f"{self.robot}: {EQUATION}", ""]
        lines.append(f"{'joint':26s} {'q':>14s} {'v':>16s} {'a':>18s} {'tau':>16s} {'G':>16s}")
        q_offset = len(self.q) - len(self.v)  # a floating base has one more q than v entries
        for dof in self.dofs:
            index = dof.index
            q_text = "(base)" if dof.is_base else f"{self.q[index + q_offset]:.{precision}g} {dof.position_unit}"
            lines.append(
                f"{dof.name:26s} {q_text:>14s} {self.v[index]:>{10}.{precision}g} {dof.velocity_unit:5s} "
                f"{self.a[index]:>{10}.{precision}g} {dof.acceleration_unit:7s} "
                f"{self.tau[index]:>{11}.{precision}g} {dof.effort_unit:4s} "
                f"{self.G[index]:>{11}.{precision}g} {dof.effort_unit:4s}"
            )
        lines += ["", "M(q), mass matrix (SI: kg m² between revolute joints, kg between prismatic, kg m mixed):"]
        lines += _matrix(self.M, precision)
        lines += ["", "C(q, v), Coriolis matrix (SI: the units of M per second; C v is in the units of tau):"]
        lines += _matrix(self.C, precision)
        return "\n".join(printable(line) for line in lines)


def dynamics_terms(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> DynamicsTerms:
    """Evaluate ``tau``, ``M``, ``C`` and ``G`` at one state (1-D arrays: q (nq,), v and a (nv,)).

    Args:
        robot: The robot.
        q: Configuration, shape (nq,), in [rad] / [m].
        v: Velocity, shape (nv,), in [rad/s] / [m/s].
        a: Acceleration, shape (nv,), in [rad/s²] / [m/s²].
    """
    return DynamicsTerms(
        robot.name, tuple(robot.joint_names), robot.dofs,
        np.asarray(q, float), np.asarray(v, float), np.asarray(a, float),
        robot.inverse_dynamics(q, v, a), robot.mass_matrix(q), robot.coriolis_matrix(q, v), robot.gravity(q),
    )  # fmt: skip


def _matrix(matrix: np.ndarray, precision: int) -> list[str]:
    width = precision + 7
    return ["  [" + " ".join(f"{value:{width}.{precision}g}" for value in row) + " ]" for row in matrix]
