"""One entry point for every document the equations layer writes: :func:`equations_document`.

``robodyn equations --symbolic`` (and ``--christoffel``, ``--kinematics``, ``--derivation``,
``--lecture``) call this one function and print or write what it returns; which document,
for which robot, in which format is decided here, with every refusal made before the
derivation starts.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Literal, cast

from robodyn.common.text import counted, printable, quoted
from robodyn.constraints import as_constraints, from_equalities
from robodyn.equations.christoffel import render_christoffel
from robodyn.equations.constrained_document import constrained_derivation_document
from robodyn.equations.derive import Form, derive_equations
from robodyn.equations.kinematics import KinematicsFormat, derive_kinematics, render_kinematics
from robodyn.equations.lecture import lecture_text
from robodyn.equations.output import Format, render
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision
from robodyn.equations.render_derivation import DerivationFormat, derivation_document
from robodyn.equations.render_latex import tex_engine
from robodyn.exceptions import InputError, MissingToolError, RobodynWarning
from robodyn.urdf.sources import resolve_source

#: Which document: the equations of motion, their Christoffel symbols, a frame's
#: kinematics, the Lagrangian derivation step by step, or the lecture's RP arm with errata.
What = Literal["equations", "christoffel", "kinematics", "derivation", "lecture"]
#: The formats each document comes in.
FORMATS: dict[str, tuple[str, ...]] = {
    "equations": ("text", "latex", "pdf", "json", "python", "c"),
    "christoffel": ("text", "json"),
    "kinematics": ("text", "latex", "json", "python", "c"),
    "derivation": ("text", "latex", "pdf", "json"),
    "lecture": ("text",),
}
#: The robot the lecture derives.
LECTURE_ROBOT = "rp_arm"

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True)
class Document:
    """A document of the equations layer.

    Attributes:
        content: The document (``bytes`` for a PDF).
        description: What it is, for a message (``"compact form, 755 operations"``).
    """

    content: str | bytes
    description: str


@dataclass(frozen=True)
class Request:
    """What :func:`equations_document` is asked for (its keyword arguments)."""

    format: str = "text"
    form: Form = "auto"
    keep_params: bool = False
    gravity: Sequence[float] | None = None
    lock: dict[str, float] | None = None
    floating_base: bool | None = None
    frame: str | None = None
    precision: int = DEFAULT_PRECISION
    xacro_args: Mapping[str, str] | None = None
    packages: Mapping[str, str] | None = None
    xacro_env: bool = False
    constraints: object = None


def equations_document(
    source: str | os.PathLike,
    what: What = "equations",
    *,
    progress: Progress | None = None,
    **options: object,
) -> Document:
    """One document of a robot's equations, refused before any work when it cannot be made.

    Args:
        source: Anything :func:`robodyn.load` takes.
        what: Which document (:data:`What`).
        progress: Called as ``progress(stage, done, total)`` during long derivations.
        **options: The fields of :class:`Request`: ``format`` (one of :data:`FORMATS` for
            ``what``), ``form``, ``keep_params``, ``gravity`` in [m/s²], ``lock``,
            ``floating_base``, ``frame`` (a link, for ``"kinematics"``), ``precision``,
            ``xacro_args``, ``packages``, ``xacro_env`` and ``constraints`` (as for
            :func:`robodyn.load`: added to the file's ``<equality>``).

    Raises:
        InputError: For a format the document does not come in, a lecture of another
            robot, kinematics without a frame, and whatever the derivation refuses.
        MissingToolError: For a PDF without pdflatex.
    """
    request = Request(**options)  # type: ignore[arg-type]
    if request.xacro_args or request.packages or request.xacro_env:  # read once, as robodyn.load reads it
        source = resolve_source(
            source, xacro_args=request.xacro_args, packages=request.packages, xacro_env=request.xacro_env
        ).text
    _check(source, what, request)
    if what == "lecture":
        return Document(lecture_text(), "the lecture's RP arm")
    constraints = _constraints(source, request.constraints)
    if what == "derivation" and constraints:
        constrained = constrained_derivation_document(
            source, constraints, format=request.format, gravity=request.gravity, precision=request.precision,
            keep_params=request.keep_params, lock=request.lock,
        )  # fmt: skip
        return Document(constrained, "derivation with multipliers")
    _note_constraints(source, request.constraints)
    if what == "derivation":
        content = derivation_document(
            source, format=cast(DerivationFormat, request.format), keep_params=request.keep_params,
            gravity=request.gravity, lock=request.lock, precision=request.precision,
        )  # fmt: skip
        return Document(content, "derivation")
    if what == "kinematics":
        kinematics = derive_kinematics(source, cast(str, request.frame), lock=request.lock, progress=progress)
        return Document(
            render_kinematics(kinematics, cast(KinematicsFormat, request.format), precision=request.precision), "kinematics"
        )
    equations = derive_equations(
        source, form=request.form, keep_params=request.keep_params, gravity=request.gravity, lock=request.lock,
        floating_base=request.floating_base, progress=progress,
    )  # fmt: skip
    if what == "christoffel":
        symbols = render_christoffel(equations, cast(Literal["text", "json"], request.format), precision=request.precision)
        return Document(symbols, "Christoffel")
    output = render(equations, cast(Format, request.format), precision=request.precision)
    return Document(output, f"{equations.form} form, {equations.operation_count()} operations")


def _check(source: str | os.PathLike, what: str, request: Request) -> None:
    """The refusals made before any derivation (:func:`equations_document`'s Raises)."""
    check_precision(request.precision)
    if what not in FORMATS:
        raise InputError("what", f"one of {', '.join(FORMATS)}", repr(what))
    if request.format not in FORMATS[what]:
        raise InputError("format", f"one of {', '.join(FORMATS[what])} for the {what}", repr(request.format))
    if request.format == "pdf" and tex_engine() is None:
        raise MissingToolError("pdflatex", "a PDF", "install TeX Live (Debian: texlive-latex-base) or use format='latex'")
    if what == "lecture" and source != LECTURE_ROBOT:
        raise InputError("model", f"{LECTURE_ROBOT} for the lecture (the lecture's arm)", repr(printable(str(source))))
    if what == "kinematics" and not request.frame:
        raise InputError("frame", "a link of the robot for its kinematics", repr(request.frame))


def _constraints(source: str | os.PathLike, given: object) -> tuple:
    """The robot's constraints: its file's ``<equality>``, then ``given``."""
    return (*from_equalities(resolve_source(source).equalities), *as_constraints(given))


def _note_constraints(source: str | os.PathLike, given: object) -> None:
    """One warning line when the robot has constraints (its file's ``<equality>``, or
    ``constraints=``): the equations derived are the open tree's, never silently the
    constrained robot's."""
    resolved = resolve_source(source)
    named = [record.name or record.kind for record in resolved.equalities]
    added = [constraint.name or constraint.kind for constraint in as_constraints(given)]
    noun = "constraint" if added else "equality constraint"
    named += added
    if named:
        names = ", ".join(quoted(name) for name in named[:4])
        warnings.warn(
            f"{resolved.label}: these equations are the open tree's; not in them: "
            f"{counted(len(named), noun)} ({names}) "
            "(Robot.constrained_forward_dynamics gives q̈ and λ; docs/constraints.md)",
            RobodynWarning,
            stacklevel=3,
        )
