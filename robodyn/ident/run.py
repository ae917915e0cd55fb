"""Identification runs with their files: :func:`identify_run` and :func:`excite_run`, their
text and their JSON.

:func:`identify_run` identifies the base parameters from measured data
(:func:`robodyn.ident.identify`), optionally writes the result as JSON and (with the
``"physical"`` method) the identified URDF, and returns an :class:`IdentificationRun` whose
:meth:`~IdentificationRun.text` is the table ``robodyn identify`` prints. :func:`excite_run`
optimises an exciting trajectory, samples it and writes it as a trajectory file
(:class:`ExcitationRun`, what ``robodyn excite`` prints).
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol, cast

import numpy as np

from robodyn.common.files import atomic_write_text
from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.ident.base import base_parameters
from robodyn.ident.excitation import Excitation, excite
from robodyn.ident.identify import Identification, Method, Samples, identify
from robodyn.ident.urdf_out import identified_urdf
from robodyn.trajectory import Trajectory


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
    bodies: Sequence[str] | None = None,
    out: str | os.PathLike | None = None,
    urdf_out: str | os.PathLike | None = None,
) -> IdentificationRun:
    """Identify ``robot``'s base parameters from ``data`` and write the files asked for.

    Args:
        robot: The nominal robot.
        data: Measured ``q``, ``v``, ``a`` and ``tau`` (a trajectory with torques).
        method: ``"ls"``, ``"wls"`` or ``"physical"``.
        friction: Identify viscous and Coulomb friction per joint too.
        bodies: Identify only these bodies (link names of
            :func:`robodyn.dynamics.regressor.body_links`); the others are held at the
            URDF's values. Default: every body. With ``urdf_out`` only these links'
            ``<inertial>`` change; without it the physical fit may move mass between
            links that the data cannot tell apart (e.g. when only a payload is unknown).
        out: Write the result as JSON to this file.
        urdf_out: With ``method="physical"``: write the identified URDF to this file.

    Raises:
        InputError: Naming ``data`` without torques, or ``urdf_out`` with another method.
    """
    if urdf_out and method != "physical":
        raise InputError("urdf_out", "used with method 'physical' (only it gives consistent standard parameters)", method)
    if data.tau is None:
        raise InputError("data", "a trajectory with tau[<joint>] columns (the measured torques)", "none")
    base = base_parameters(robot, friction=friction, bodies=None if bodies is None else list(bodies))
    result = identify(robot, cast(Samples, data), method=method, base=base)  # tau checked above
    urdf = identified_urdf(robot, result.standard, base.columns) if urdf_out and result.standard is not None else None
    if out:
        atomic_write_text(out, json.dumps(result.to_dict(), indent=2) + "\n")
    if urdf is not None and urdf_out:
        atomic_write_text(urdf_out, urdf)
    return IdentificationRun(result, str(out) if out else None, str(urdf_out) if urdf is not None and urdf_out else None)


@dataclass(frozen=True)
class ExcitationRun:
    """An exciting trajectory, sampled and written as a trajectory file.

    Attributes:
        excitation: The optimised excitation (coefficients, condition numbers).
        base_count: Number of base parameters it excites.
        harmonics: Harmonics per joint.
        rate: Sampling rate of the file in [Hz].
        samples: Rows written.
        out: The trajectory file written.
    """

    excitation: Excitation
    base_count: int
    harmonics: int
    rate: float
    samples: int
    out: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the period [s], harmonics, condition numbers and the file."""
        excitation = self.excitation
        return {
            "robot": excitation.robot,
            "base_parameters": self.base_count,
            "period_s": excitation.period,
            "harmonics": self.harmonics,
            "condition_number": excitation.condition,
            "initial_condition_number": excitation.initial_condition,
            "improved": excitation.improved,
            "samples": self.samples,
            "rate_hz": self.rate,
            "out": self.out,
        }

    def text(self) -> str:
        """What ``robodyn excite`` prints: the base parameters, the conditioning, the file."""
        excitation = self.excitation
        conditioning = (
            f"condition number of the stacked base regressor: {excitation.condition:.4g} "
            f"(start {excitation.initial_condition:.4g})"
            if excitation.improved
            else f"not optimised: no point better than the random start was found; its condition number "
            f"{excitation.condition:.4g}"
        )
        return "\n".join(
            [
                f"{printable(excitation.robot)}: {self.base_count} base parameters; "
                f"excitation of {excitation.period:g} s, {self.harmonics} harmonics",
                conditioning,
                f"wrote {self.out} ({self.samples} samples at {self.rate:g} Hz)",
            ]
        )


def excite_run(
    robot: Robot,
    *,
    out: str | os.PathLike,
    rate: float = 100.0,
    harmonics: int = 5,
    **options: Any,
) -> ExcitationRun:
    """An exciting trajectory for ``robot`` (:func:`robodyn.ident.excite`), sampled at
    ``rate`` [Hz] with the model's inverse dynamics as ``tau`` and written to ``out``
    (.csv or .npz, the trajectory format).

    Args:
        robot: A fixed-base robot.
        out: The trajectory file to write.
        rate: Sampling rate in [Hz].
        harmonics: Harmonics per joint.
        **options: The other keyword arguments of :func:`robodyn.ident.excite`
            (``duration``, ``velocity_limit``, ``acceleration_limit``, ``iterations``, ``seed``).
    """
    base = base_parameters(robot)
    excitation = excite(robot, harmonics=harmonics, base=base, **options)
    t, q, v, a, tau = excitation.sample(robot, rate=rate)
    Trajectory(t, q, v, a, tau, list(robot.joint_names), robot.name).save(os.fspath(out))
    return ExcitationRun(excitation, base.count, harmonics, rate, len(t), str(out))
