"""URDF in, equations out: ``tau = M(q) q̈ + C(q, q̇) q̇ + G(q)`` derived symbolically.

:func:`derive_equations` asks the independent reference for the equations (never
Pinocchio): small chains (``form="closed"``) as simplified expressions from the symbolic
Lagrangian (:mod:`robodyn.reference.symbolic`, then :mod:`robodyn.equations.simplify`);
larger ones (``form="compact"``) as a short program of named intermediate variables
(:mod:`robodyn.equations.compact`). Numbers are exact until output. The renderers
(:func:`robodyn.equations.output.render`) turn the result into text, LaTeX, PDF, JSON, a
standalone Python module (numpy only) or C source.

Symbols are safe identifiers named after the joints (:func:`robodyn.common.text.identifier`):
``q_<joint>``, ``qd_<joint>`` (velocity), ``qdd_<joint>`` (acceleration). With
``keep_params`` every link's mass ``m_<link>``, centre of mass ``c_<link>_x``..., inertia
``I_<link>_xx``..., every joint's offset ``d_<joint>_x``... and gravity ``g`` stay symbols.
Mimic joints follow their leader through ``q_full = S q + offset``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any, Literal

import sympy as sp

from robodyn import reference
from robodyn.common.text import identifier
from robodyn.equations import simplify
from robodyn.equations.compact import SNAP, derive_compact
from robodyn.equations.model import EquationsData
from robodyn.equations.output import FORMATS, render
from robodyn.equations.render_latex import latex_math
from robodyn.exceptions import DerivationTooExpensiveError, InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import derive, exact_matrix, exact_number
from robodyn.reference.tree import Body
from robodyn.urdf.sources import resolve_source

__all__ = [
    "AUTO_CLOSED_FORM_S",
    "CLOSED_FORM_JOINTS",
    "FORMATS",
    "Equations",
    "derive_equations",
    "estimate_closed_form_seconds",
    "render",
]

Form = Literal["auto", "closed", "compact"]

#: Largest number of joints derived in closed form by ``form="auto"``.
CLOSED_FORM_JOINTS = 3
#: A closed-form derivation estimated to take longer than this is refused, in [s].
CLOSED_FORM_LIMIT_S = 30.0
#: ``form="auto"`` takes the compact form when the closed one is estimated longer, in [s].
AUTO_CLOSED_FORM_S = 5.0


class Equations(EquationsData):
    """Symbolic equations of motion (see :class:`robodyn.equations.model.EquationsData`),
    shown as LaTeX in notebooks."""

    def _repr_latex_(self) -> str:
        """The equations for notebooks (Jupyter renders this with MathJax)."""
        return latex_math(self)


def _complexity(body: Body) -> float:
    """How much a joint's frame multiplies the closed form's cost: 7 for an axis off the
    joint frame's x, y, z; 2 for an origin turned by other than right angles (rotation
    entries that are long rationals, not 0, ±1, ±½...); else 1."""
    axis = exact_matrix(body.axis[:, None], SNAP)
    if sum(x != 0 for x in axis) > 1:
        return 7.0
    rotation = exact_matrix(body.origin[:3, :3], SNAP)
    return 2.0 if any(isinstance(x, sp.Rational) and x.q > 2 for x in rotation) else 1.0


def estimate_closed_form_seconds(robot: ReferenceRobot, *, keep_params: bool = False) -> float:
    """A rough estimate of the closed form's derivation time, in [s].

    The Lagrangian's expressions grow about tenfold with each revolute body of a chain
    (a mimic joint's body included) and threefold with each prismatic one; a mimic joint
    adds angles ``a q + b`` (1.5-fold more); an oblique axis sevenfold, an origin turned
    by other than right angles twofold (:func:`_complexity`). CPU time measured (estimate):
    rp_arm 0.2 s (0.15), the double pendulum 0.66 s (0.5), a revolute–revolute–prismatic
    arm 1.5 s (1.5), the mimic arm (two coordinates, three bodies) 7.5 s (7.5), that
    arm with a prismatic joint before the wrist 16 s (22.5), and with the wrist's origin
    turned by 0.3 rad 30 s (45), a two-joint arm with one origin turned by 0.3 rad 1.1 s
    (1.0), the oblique robot's first joint 0.28 s (0.35) and first two 28 s (24.5), ur5's
    first four joints 52 s. Kept parameters cost about as much again.

    Args:
        robot: The reference model of the robot.
        keep_params: Estimate for symbolic parameters (slower) instead of numbers.
    """
    bodies = [body for body in robot.tree.bodies if not body.rotor]  # a rotor adds one term, not a level
    revolute = sum(body.revolute for body in bodies)
    mimic = len(bodies) - robot.nv
    estimate = 0.005 * 10.0**revolute * 3.0 ** (len(bodies) - revolute) * 1.5**mimic
    for body in bodies:
        estimate *= _complexity(body)
    return estimate * (3.0 if keep_params else 1.0)


def _symbols(joint_names: list[str], taken: set[str]) -> tuple[list[sp.Symbol], ...]:
    return tuple(
        [sp.Symbol(identifier(name, taken, prefix=prefix), real=True) for name in joint_names] for prefix in ("q_", "qd_", "qdd_")
    )


def _safe_parameters(
    values: dict[sp.Symbol, float], labels: dict[sp.Symbol, tuple[str, str, str]], taken: set[str]
) -> tuple[dict[sp.Symbol, sp.Symbol], dict[sp.Symbol, float], dict[sp.Symbol, tuple[str, str, str]]]:
    """Rename kept parameters (named after links and joints) to safe identifiers."""
    rename = {symbol: sp.Symbol(identifier(symbol.name, taken), real=True) for symbol in sorted(values, key=str)}
    return (
        rename,
        {rename[s]: v for s, v in values.items()},
        {rename[s]: label for s, label in labels.items()},
    )


def _check_request(source: str | os.PathLike, form: Form, floating_base: bool | None) -> None:
    """Refuse an unknown form or a floating base (before the robot is loaded)."""
    if form not in ("auto", "closed", "compact"):
        raise InputError("form", "closed, compact or auto", repr(form))
    if floating_base or (floating_base is None and resolve_source(source).floating_base):
        raise InputError(
            "floating_base", "False: symbolic equations model fixed bases (floating_base=False)", f"a floating {source}"
        )


def _compact_form(
    model: ReferenceRobot,
    symbols: tuple[list[sp.Symbol], ...],
    taken: set[str],
    *,
    keep_params: bool,
    progress: Callable[[str, int, int], None] | None,
) -> dict[str, Any]:
    """The compact form's fields of :class:`Equations` (kept parameters renamed safely)."""
    q, qd, qdd = symbols
    compact = derive_compact(model, keep_params=keep_params, symbols=(q, qd, qdd), progress=progress)
    rename, parameters, labels = _safe_parameters(compact.parameters, compact.labels, taken)
    return {
        "form": "compact",
        "assignments": [(s, e.xreplace(rename)) for s, e in compact.assignments],
        "M": compact.M.xreplace(rename),
        "Cv": compact.Cv.xreplace(rename),
        "G": compact.G.xreplace(rename),
        "parameters": parameters,
        "labels": labels,
    }


def _closed_form(
    model: ReferenceRobot,
    symbols: tuple[list[sp.Symbol], ...],
    taken: set[str],
    *,
    keep_params: bool,
    progress: Callable[[str, int, int], None] | None,
) -> dict[str, Any]:
    """The closed form's fields of :class:`Equations`: the Lagrangian, each entry simplified."""
    q, qd, qdd = symbols
    if progress:
        progress("Lagrangian", 0, 3)
    closed = derive(model, keep_params=keep_params, symbols=(q, qd, qdd), simplify=False)
    rename, parameters, labels = _safe_parameters(closed.parameters, closed.labels, taken)
    if progress:
        progress("simplification", 1, 3)
    raw = {name: m.xreplace(rename) for name, m in (("M", closed.M), ("C", closed.C), ("G", closed.G))}
    raw["Cv"] = raw["C"] * sp.Matrix(qd)
    # Round-off floor of a matrix: RELATIVE_ROUND_OFF of its largest coefficient (C and C q̇
    # are M's derivatives: at least M's), so an entry made of round-off alone goes too.
    scale = {name: simplify.largest_coefficient(m) for name, m in raw.items()}
    tidied = {}
    for name, matrix in raw.items():
        floor = simplify.RELATIVE_ROUND_OFF * max(scale[name], scale["M"] if name in ("C", "Cv") else 0.0)
        tidied[name] = matrix.applyfunc(lambda e, f=floor: simplify.entry(e, q, qd, floor=f))
    M, C, Cv, G = (tidied[name] for name in ("M", "C", "Cv", "G"))
    used = set().union(*(m.free_symbols for m in (M, C, G)))
    if progress:
        progress("simplification", 3, 3)
    return {
        "form": "closed",
        "assignments": [],
        "M": M,
        "Cv": Cv,
        "G": G,
        "C": C,
        "parameters": {s: v for s, v in parameters.items() if s in used},
        "labels": {s: label for s, label in labels.items() if s in used},
    }


def derive_equations(
    source: str | os.PathLike,
    *,
    form: Form = "auto",
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
    floating_base: bool | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> Equations:
    """Derive the equations of motion of a robot symbolically.

    Args:
        source: Anything :func:`robodyn.load` takes.
        form: ``"closed"``, ``"compact"`` or ``"auto"`` (closed up to three joints when
            estimated to take at most :data:`AUTO_CLOSED_FORM_S`; see
            :func:`estimate_closed_form_seconds`). The result's ``form`` says which.
        keep_params: Keep masses, centres of mass, inertias, joint offsets and gravity as
            symbols (both forms; code output then refuses, it needs numbers).
        gravity: Gravity in the world frame, in [m/s²]; default ``(0, 0, -9.81)``.
        lock: Joints to freeze, by name, at positions (e.g. a gripper's fingers).
        floating_base: As for :func:`robodyn.load`; symbolic equations model fixed bases,
            so a robot that would load floating must be asked for with ``False``.
        progress: Called as ``progress(stage, done, total)`` during long derivations.

    Raises:
        InputError: For a floating base or a bad form.
        DerivationTooExpensiveError: For a closed form estimated to take longer than
            :data:`CLOSED_FORM_LIMIT_S` (the compact form is fast).
    """
    _check_request(source, form, floating_base)
    model = reference.load(source, lock=lock, gravity=gravity)
    if form == "auto":
        fast = estimate_closed_form_seconds(model, keep_params=keep_params) <= AUTO_CLOSED_FORM_S
        form = "closed" if model.nv <= CLOSED_FORM_JOINTS and fast else "compact"
    if form == "closed":
        estimate = estimate_closed_form_seconds(model, keep_params=keep_params)
        if estimate > CLOSED_FORM_LIMIT_S:
            raise DerivationTooExpensiveError(model.name, model.nv, estimate, CLOSED_FORM_LIMIT_S)
    taken: set[str] = set()
    symbols = _symbols(model.joint_names, taken)
    derived = (_compact_form if form == "compact" else _closed_form)(
        model, symbols, taken, keep_params=keep_params, progress=progress
    )
    q, qd, qdd = symbols
    return Equations(
        robot=model.name,
        joint_names=list(model.joint_names),
        gravity=(float(model.gravity_vector[0]), float(model.gravity_vector[1]), float(model.gravity_vector[2])),
        q=q,
        qd=qd,
        qdd=qdd,
        **derived,
    )


def substitute_parameters(equations: EquationsData) -> EquationsData:
    """The equations with every kept parameter replaced by its (exact) value.

    Args:
        equations: Equations derived with kept (symbolic) parameters.
    """
    values = {s: exact_number(v) for s, v in equations.parameters.items()}
    matrices: dict[str, Any] = {
        name: getattr(equations, name).xreplace(values) if getattr(equations, name) is not None else None
        for name in ("M", "Cv", "G", "C")
    }
    return replace(
        equations, assignments=[(s, e.xreplace(values)) for s, e in equations.assignments], parameters={}, labels={}, **matrices
    )
