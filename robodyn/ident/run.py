"""An identification run with its files: :func:`identify_run`, its text and its JSON.

:func:`identify_run` identifies the base parameters from measured data
(:func:`robodyn.ident.identify`), optionally writes the result as JSON and (with the
``"physical"`` method) the identified URDF, and returns an :class:`IdentificationRun` whose
:meth:`~IdentificationRun.text` is the table ``robodyn identify`` prints.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, Protocol, cast

import numpy as np

from robodyn.common.files import atomic_write_text
from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.ident.base import base_parameters
from robodyn.ident.identify import Identification, Method, Samples, identify
from robodyn.ident.urdf_out import identified_urdf


class Measured(Protocol):
    """Measured data that may lack torques (a trajectory file read without ``tau`` columns)."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray | None
    joint_names: list[str]


@dataclass(frozen=True)
class IdentificationRun:
    """An identification and the files written of it.

    Attributes:
        identification: The result (values, standard deviations, errors).
        out: The JSON file written of it, if any.
        urdf_out: The identified URDF written, if any.
    """

    identification: Identification
    out: str | None = None
    urdf_out: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: :meth:`Identification.to_dict` (what ``out`` holds)."""
        return self.identification.to_dict()

    def text(self) -> str:
        """The identified parameters beside the URDF's, one line each, then the files written."""
        result = self.identification
        base = result.base
        width = max(len(printable(name)) for name in base.names)
        lines = [
            f"{printable(base.robot.name)}: {result.method} identification of {base.count} base parameters "
            f"from {result.samples} samples",
            f"condition number {result.condition:.4g}; relative torque error {result.relative_error:.3g}",
            "",
            f"{'parameter':{width}s} {'identified':>12s} {'std':>10s} {'URDF':>12s}",
        ]
        for name, value, std, nominal in zip(base.names, result.values, result.std, base.values, strict=True):
            lines.append(f"{printable(name):{width}s} {value:>12.6g} {std:>10.3g} {nominal:>12.6g}")
        if self.out is not None:
            lines += ["", f"wrote {self.out}"]
        if self.urdf_out is not None:
            lines.append(f"wrote {self.urdf_out}")
        return "\n".join(lines)


def identify_run(
    robot: Robot,
    data: Measured,
    *,
    method: Method = "ls",
    friction: bool = False,
    out: str | os.PathLike | None = None,
    urdf_out: str | os.PathLike | None = None,
) -> IdentificationRun:
    """Identify ``robot``'s base parameters from ``data`` and write the files asked for.

    Args:
        robot: The nominal robot.
        data: Measured ``q``, ``v``, ``a`` and ``tau`` (a trajectory with torques).
        method: ``"ls"``, ``"wls"`` or ``"physical"``.
        friction: Identify viscous and Coulomb friction per joint too.
        out: Write the result as JSON to this file.
        urdf_out: With ``method="physical"``: write the identified URDF to this file.

    Raises:
        InputError: Naming ``data`` without torques, or ``urdf_out`` with another method.
    """
    if urdf_out and method != "physical":
        raise InputError("urdf_out", "used with method 'physical' (only it gives consistent standard parameters)", method)
    if data.tau is None:
        raise InputError("data", "a trajectory with tau[<joint>] columns (the measured torques)", "none")
    base = base_parameters(robot, friction=friction)
    result = identify(robot, cast(Samples, data), method=method, base=base)  # tau checked above
    urdf = identified_urdf(robot, result.standard, base.columns) if urdf_out and result.standard is not None else None
    if out:
        atomic_write_text(out, json.dumps(result.to_dict(), indent=2) + "\n")
    if urdf is not None and urdf_out:
        atomic_write_text(urdf_out, urdf)
    return IdentificationRun(result, str(out) if out else None, str(urdf_out) if urdf is not None and urdf_out else None)
