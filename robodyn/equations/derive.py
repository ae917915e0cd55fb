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
from robodyn.equations.compact import derive_compact
from robodyn.equations.model import EquationsData
from robodyn.equations.output import FORMATS, render
from robodyn.equations.render_latex import latex_math
from robodyn.exceptions import DerivationTooExpensiveError, InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import derive, exact_number
from robodyn.urdf.sources import resolve_source

__all__ = ["CLOSED_FORM_JOINTS", "FORMATS", "Equations", "derive_equations", "estimate_closed_form_seconds", "render"]

Form = Literal["auto", "closed", "compact"]

#: Largest number of joints derived in closed form by ``form="auto"``.
CLOSED_FORM_JOINTS = 3
#: A closed-form derivation estimated to take longer than this is refused, in [s].
CLOSED_FORM_LIMIT_S = 30.0


class Equations(EquationsData):
    """Symbolic equations of motion (see :class:`robodyn.equations.model.EquationsData`),
    shown as LaTeX in notebooks."""

    def _repr_latex_(self) -> str:
        """The equations for notebooks (Jupyter renders this with MathJax)."""
        return latex_math(self)


def estimate_closed_form_seconds(robot: ReferenceRobot, *, keep_params: bool = False) -> float:
    """A rough estimate of the closed form's derivation time, in [s].

    The Lagrangian's expressions grow about tenfold with each revolute joint of a chain
    and threefold with each prismatic one (CPU time measured: rp_arm 0.2 s, the double
    pendulum 0.5 s, a revolute–revolute–prismatic arm 1.5 s, ur5's first four joints 52 s);
    kept parameters cost about as much again.
    """
    bodies = robot.tree.bodies
    revolute = sum(body.revolute for body in bodies)
    estimate = 0.005 * 10.0**revolute * 3.0 ** (len(bodies) - revolute)
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
        form: ``"closed"``, ``"compact"`` or ``"auto"`` (closed up to three joints).
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
        form = "closed" if model.nv <= CLOSED_FORM_JOINTS else "compact"
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
    """The equations with every kept parameter replaced by its (exact) value."""
    values = {s: exact_number(v) for s, v in equations.parameters.items()}
    matrices: dict[str, Any] = {
        name: getattr(equations, name).xreplace(values) if getattr(equations, name) is not None else None
        for name in ("M", "Cv", "G", "C")
    }
    return replace(
        equations, assignments=[(s, e.xreplace(values)) for s, e in equations.assignments], parameters={}, labels={}, **matrices
    )
