"""The lecture's Lagrangian derivation, worked step by step for a small robot.

The steps a lecture writes by hand, for any fixed-base chain or tree of up to
:data:`MAX_MOVING_JOINTS` moving joints (mimic joints included), from the reference's
kinematic tree (:mod:`robodyn.reference.symbolic`; never Pinocchio):

1. every link's frame ``R_i(q)`` and centre of mass in the world ``p_i(q)``;
2. its linear velocity ``v_i = J_{v,i} q̇`` and angular velocity ``ω_i = J_{ω,i} q̇``;
3. ``T_i = ½ m_i v_iᵀ v_i + ½ ω_iᵀ R_i I_i R_iᵀ ω_i`` and ``U_i = −m_i gᵀ p_i``;
4. ``L = Σ T_i − Σ U_i``;
5. for each joint ``∂L/∂q̇_i``, ``d/dt ∂L/∂q̇_i = Σ_j ∂²L/∂q̇_i∂q_j q̇_j + ∂²L/∂q̇_i∂q̇_j q̈_j``,
   ``∂L/∂q_i`` and ``τ_i = d/dt ∂L/∂q̇_i − ∂L/∂q_i``;
6. the matrix form ``τ = M q̈ + C q̇ + G``, each entry traced to step 5:
   ``M_ij = ∂²L/∂q̇_i∂q̇_j`` (the coefficient of ``q̈_j`` in ``d/dt ∂L/∂q̇_i``),
   ``(C q̇)_i = Σ_j ∂²L/∂q̇_i∂q_j q̇_j − ∂T/∂q_i`` (the velocity products of step 5),
   ``G_i = ∂U/∂q_i`` (the rest of ``−∂L/∂q_i``); ``C`` itself by the Christoffel symbols.

Every expression is exact (URDF numbers as rationals) and simplified the way the
equations are (:func:`robodyn.equations.simplify.entry`). Symbols are those of the
equations: ``q_<joint>``, ``qd_<joint>``, ``qdd_<joint>``; with ``keep_params`` the kept
parameters of :func:`robodyn.equations.derive_equations` (``m_<link>``, ``c_<link>_x``...,
``g``), and for the lecture's RP arm the lecture's own symbols ``m1, m2, l1, c2, Iz1, Iz2, g``
with the slides' errata (:data:`robodyn.equations.lecture.ERRATA`) marked at the step where
each one enters (:data:`LECTURE_ERRATA_STEPS`).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy as sp

from robodyn import reference
from robodyn.common.text import identifier
from robodyn.equations import lecture, simplify
from robodyn.exceptions import InputError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import Parameters, body_coordinates, body_poses

#: Largest number of moving joints (mimic joints included) worked step by step.
MAX_MOVING_JOINTS = 4
#: The robot whose derivation follows the lecture's slides (its symbols, its errata).
LECTURE_ROBOT = "rp_arm"
#: Step (a key of :meth:`DerivationSteps` dictionaries) where each erratum of the lecture enters.
LECTURE_ERRATA_STEPS = {3: "p", 1: "U", 2: "ddt_dL_dqd"}
#: The rp_arm's kept parameters in the lecture's symbols (see ``lecture.in_lecture_symbols``).
LECTURE_SYMBOLS = {
    "m_link1": lecture.m1,
    "c_link1_x": lecture.l1 / 2,
    "I_link1_yy": lecture.Iz1,
    "d_joint2_x": lecture.l1,
    "m_link2": lecture.m2,
    "c_link2_x": lecture.c2,
    "I_link2_yy": lecture.Iz2,
    "g": lecture.g,
}


@dataclass(frozen=True)
class LinkTerms:
    """Steps 1–3 for one moving body (a link and the links welded to it).

    Attributes:
        link: The body's link, as named in the URDF.
        joint: The joint that moves it, as named in the URDF.
        mass: ``m_i`` in [kg] (a number, or a kept symbol).
        R: World rotation of the body's frame (3 × 3).
        inertia: ``I_i`` about the centre of mass, body-frame axes, in [kg m²] (3 × 3).
        p: Centre of mass in the world, in [m] (3 × 1).
        Jv, Jw: ``∂p_i/∂q`` and the angular Jacobian (3 × n).
        v, omega: ``J_{v,i} q̇`` in [m/s] and ``J_{ω,i} q̇`` in [rad/s] (3 × 1).
        T, U: Kinetic and potential energy in [J].
    """

    link: str
    joint: str
    mass: sp.Expr
    R: sp.Matrix
    inertia: sp.Matrix
    p: sp.Matrix
    Jv: sp.Matrix
    Jw: sp.Matrix
    v: sp.Matrix
    omega: sp.Matrix
    T: sp.Expr
    U: sp.Expr


@dataclass(frozen=True)
class JointTerms:
    """Step 5 for one joint, and the pieces step 6 is traced to.

    Attributes:
        joint: As named in the URDF.
        dL_dqd, ddt_dL_dqd, dL_dq, tau: ``∂L/∂q̇_i``, ``d/dt ∂L/∂q̇_i``, ``∂L/∂q_i`` and
            ``τ_i`` in [N m] or [N].
        velocity_terms: The velocity products of ``d/dt ∂L/∂q̇_i``: ``Σ_j ∂²L/∂q̇_i∂q_j q̇_j``.
        dT_dq, dU_dq: ``∂T/∂q_i`` and ``∂U/∂q_i`` (``∂L/∂q_i = ∂T/∂q_i − ∂U/∂q_i``).
    """

    joint: str
    dL_dqd: sp.Expr  # noqa: N815 (the lecture's names)
    ddt_dL_dqd: sp.Expr  # noqa: N815 (the lecture's names)
    dL_dq: sp.Expr  # noqa: N815 (the lecture's names)
    tau: sp.Expr
    velocity_terms: sp.Expr
    dT_dq: sp.Expr  # noqa: N815 (the lecture's names)
    dU_dq: sp.Expr  # noqa: N815 (the lecture's names)


@dataclass(frozen=True)
class DerivationSteps:
    """The Lagrangian derivation of one robot (see the module).

    Attributes:
        robot: Robot name, as in the URDF.
        joint_names: Independent joints in the order of ``q``, as in the URDF.
        q, qd, qdd: Position, velocity and acceleration symbols (safe identifiers).
        gravity: The gravity vector derived for, in [m/s²]; ``gravity_symbolic`` as used.
        links: Steps 1–3, one entry a moving body (topological order).
        L: Step 4, the Lagrangian.
        joints: Step 5, one entry a joint of ``q``.
        M, C, Cv, G: Step 6 (``C`` from the Christoffel symbols; ``Cv = C q̇``).
        parameters: Kept parameters and their values (``keep_params``).
        labels: ``(kind, owner, component)`` of every kept parameter (lecture symbols have none).
        lecture: Whether this is the lecture's RP arm (errata marked, lecture symbols).
    """

    robot: str
    joint_names: tuple[str, ...]
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    gravity: tuple[float, float, float]
    gravity_symbolic: sp.Matrix
    links: tuple[LinkTerms, ...]
    L: sp.Expr
    joints: tuple[JointTerms, ...]
    M: sp.Matrix
    C: sp.Matrix
    Cv: sp.Matrix
    G: sp.Matrix
    parameters: dict[sp.Symbol, float] = field(default_factory=dict)
    labels: dict[sp.Symbol, tuple[str, str, str]] = field(default_factory=dict)
    lecture: bool = False

    @property
    def tau(self) -> sp.Matrix:
        """``τ`` of step 5 as a column (n × 1)."""
        return sp.Matrix([joint.tau for joint in self.joints])


def _parameter_names(params: Parameters, lecture_symbols: bool) -> tuple[dict, dict, dict]:
    """Kept parameters renamed to safe identifiers, or to the lecture's symbols: the renaming,
    the values and the labels."""
    taken: set[str] = set()
    rename = {s: sp.Symbol(identifier(s.name, taken), real=True) for s in sorted(params.values, key=str)}
    values = {rename[s]: v for s, v in params.values.items()}
    labels = {rename[s]: label for s, label in params.labels.items()}
    if lecture_symbols:
        for symbol in params.values:
            if symbol.name in LECTURE_SYMBOLS:
                values.pop(rename[symbol])
                labels.pop(rename[symbol])
                rename[symbol] = LECTURE_SYMBOLS[symbol.name]
                if rename[symbol].is_Symbol:
                    values[rename[symbol]] = params.values[symbol]
    return rename, values, labels


def _link_terms(model: ReferenceRobot, q: list, qd: list, params: Parameters, gravity: sp.Matrix) -> list[dict]:
    """Steps 1–3 of every body with mass or inertia, unsimplified (plain dictionaries)."""
    tree = model.tree
    theta, theta_dot = body_coordinates(model, q, qd)
    rotations, positions, axes = body_poses(model, theta, params)
    rows = []
    for index, body in enumerate(tree.bodies):
        if body.mass == 0 and not body.inertia.any():
            continue
        rotation = rotations[index]
        p = positions[index] + rotation * params.vector(body.com, "c", body.link)
        omega = sp.zeros(3, 1)
        for ancestor in range(index + 1):
            if tree.ancestors[index, ancestor] and tree.bodies[ancestor].revolute:
                omega += axes[ancestor] * theta_dot[ancestor]
        inertia = params.inertia(body.inertia, body.link)
        mass = params.symbol(body.mass, "m", body.link)
        Jv, Jw = p.jacobian(q), omega.jacobian(qd)
        v = Jv * sp.Matrix(qd)
        world_inertia = rotation * inertia * rotation.T
        T = mass * (v.T * v)[0] / 2 + (omega.T * world_inertia * omega)[0] / 2
        U = -mass * (gravity.T * p)[0]
        rows.append(dict(link=body.link, joint=body.joint, mass=mass, R=rotation, inertia=inertia, p=p, Jv=Jv, Jw=Jw, v=v))
        rows[-1].update(omega=omega, T=T, U=U)
    return rows


def _joint_terms(L: sp.Expr, T: sp.Expr, U: sp.Expr, q: list, qd: list, qdd: list) -> list[dict]:
    """Step 5 and its parts for step 6, unsimplified (plain dictionaries)."""
    rows = []
    for qi, qdi in zip(q, qd, strict=True):
        momentum = sp.expand(sp.diff(L, qdi))
        velocity_terms = sum((sp.diff(momentum, qj) * qdj for qj, qdj in zip(q, qd, strict=True)), sp.Integer(0))
        accelerations = sum((sp.diff(momentum, qdj) * qddj for qdj, qddj in zip(qd, qdd, strict=True)), sp.Integer(0))
        ddt = velocity_terms + accelerations
        dL_dq = sp.diff(L, qi)
        rows.append(
            dict(
                dL_dqd=momentum,
                ddt_dL_dqd=ddt,
                dL_dq=dL_dq,
                tau=ddt - dL_dq,
                velocity_terms=velocity_terms,
                dT_dq=sp.diff(T, qi),
                dU_dq=sp.diff(U, qi),
            )
        )
    return rows


def _matrix_form(joints: list[dict], q: list, qd: list) -> dict[str, sp.Matrix]:
    """Step 6 from step 5's parts: ``M``, ``C`` (Christoffel), ``C q̇`` and ``G``."""
    n = len(q)
    M = sp.Matrix(n, n, lambda i, j: sp.diff(joints[i]["dL_dqd"], qd[j]))

    def christoffel(i: int, j: int, k: int) -> sp.Expr:
        return (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j]) - sp.diff(M[j, k], q[i])) / 2

    C = sp.Matrix(n, n, lambda i, j: sum((christoffel(i, j, k) * qd[k] for k in range(n)), sp.Integer(0)))
    Cv = sp.Matrix([joints[i]["velocity_terms"] - joints[i]["dT_dq"] for i in range(n)])
    G = sp.Matrix([joints[i]["dU_dq"] for i in range(n)])
    return {"M": M, "C": C, "Cv": Cv, "G": G}


def _tidy(rename: dict, q: list, speeds: list):
    """The simplifier of every step: kept parameters renamed, then as the equations are."""

    def tidy(expr):
        if isinstance(expr, sp.MatrixBase):
            return expr.applyfunc(tidy)
        return simplify.entry(sp.sympify(expr).xreplace(rename), q, speeds)

    return tidy


def _check_size(model: ReferenceRobot) -> None:
    """Refuse a robot of more than :data:`MAX_MOVING_JOINTS` moving joints, in one line."""
    moving = sum(not body.rotor for body in model.tree.bodies)  # an armature's rotor is no joint
    if moving > MAX_MOVING_JOINTS:
        raise InputError(
            "source",
            f"a robot of at most {MAX_MOVING_JOINTS} moving joints for a derivation worked step by step "
            "(derive_equations, the symbolic form, gives the equations of larger ones)",
            f"{model.name!r} with {moving}",
        )


def derive_steps(
    source: str | os.PathLike,
    *,
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
) -> DerivationSteps:
    """Work the Lagrangian derivation of a small fixed-base robot, step by step.

    Args:
        source: Anything :func:`robodyn.load` takes (loaded with a fixed base).
        keep_params: Keep masses, centres of mass, inertias, joint offsets and gravity as
            symbols (the lecture's ``m1, m2, l1, c2, Iz1, Iz2, g`` for the RP arm).
        gravity: Gravity in the world frame, in [m/s²]; default ``(0, 0, -9.81)``.
        lock: Joints to freeze, by name, at positions.

    Raises:
        InputError: For a robot with more than :data:`MAX_MOVING_JOINTS` moving joints.
    """
    model = reference.load(source, lock=lock, gravity=gravity)
    _check_size(model)
    is_lecture = model.name == LECTURE_ROBOT and list(model.joint_names) == ["joint1", "joint2"]
    taken: set[str] = set()
    q, qd, qdd = (
        [sp.Symbol(identifier(n, taken, prefix=p), real=True) for n in model.joint_names] for p in ("q_", "qd_", "qdd_")
    )
    params = Parameters(keep_params)
    gravity_symbolic = params.gravity(model.gravity_vector)
    links = _link_terms(model, q, qd, params, gravity_symbolic)
    T = sum((link["T"] for link in links), sp.Integer(0))
    U = sum((link["U"] for link in links), sp.Integer(0))
    L = sp.expand(T - U)
    joints = _joint_terms(L, T, U, q, qd, qdd)
    matrices = _matrix_form(joints, q, qd)
    rename, values, labels = _parameter_names(params, is_lecture and keep_params)
    tidy = _tidy(rename, q, [*qd, *qdd])
    link_terms = tuple(
        LinkTerms(link["link"], link["joint"], **{k: tidy(v) for k, v in link.items() if k not in ("link", "joint")})
        for link in links
    )
    joint_terms = tuple(
        JointTerms(name, **{k: tidy(v) for k, v in row.items()}) for name, row in zip(model.joint_names, joints, strict=True)
    )
    matrices = {name: tidy(matrix) for name, matrix in matrices.items()}
    used = set().union(
        *(m.free_symbols for m in matrices.values()),
        *(link.T.free_symbols | link.U.free_symbols | link.inertia.free_symbols for link in link_terms),
    )
    return DerivationSteps(
        robot=model.name,
        joint_names=tuple(model.joint_names),
        q=tuple(q),
        qd=tuple(qd),
        qdd=tuple(qdd),
        gravity=(float(model.gravity_vector[0]), float(model.gravity_vector[1]), float(model.gravity_vector[2])),
        gravity_symbolic=gravity_symbolic.xreplace(rename),
        links=link_terms,
        L=tidy(L),
        joints=joint_terms,
        **matrices,
        parameters={s: v for s, v in values.items() if s in used},
        labels={s: lbl for s, lbl in labels.items() if s in used},
        lecture=is_lecture,
    )
