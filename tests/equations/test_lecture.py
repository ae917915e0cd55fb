"""The lecture's RP derivation: each erratum of rp-arm.md shows exactly where it says."""

from __future__ import annotations

import sympy as sp

from robodyn.equations import lecture
from robodyn.equations.lecture import Iz1, Iz2, g, l1, m1, m2, q1, q2, qd1, qd2, qdd1, qdd2, split


def difference(a: sp.Matrix, b: sp.Matrix) -> dict[str, sp.Matrix]:
    parts_a, parts_b = split(a), split(b)
    return {name: sp.simplify(parts_a[name] - parts_b[name]) for name in parts_a}


def test_derivation_with_the_slides_sign_differs_from_print_only_in_the_coriolis_term():
    """Erratum 2: with the slide's own energies, the printed velocity-product term is doubled."""
    diff = difference(lecture.printed(), lecture.derived(sign=+1).tau)
    assert diff["M"] == sp.zeros(2, 1)
    assert diff["G"] == sp.zeros(2, 1)
    r = l1 + q2 / 2
    assert sp.simplify(diff["C"] - sp.Matrix([m2 * r * qd1 * qd2, 0])) == sp.zeros(2, 1)


def test_correct_potential_energy_flips_both_gravity_entries():
    """Erratum 1: U = m ḡ·P versus U = −m ḡ·P."""
    as_printed_sign = split(lecture.derived(sign=+1).tau)["G"]
    corrected = split(lecture.derived(sign=-1).tau)["G"]
    assert sp.simplify(as_printed_sign + corrected) == sp.zeros(2, 1)
    r = l1 + q2 / 2
    assert sp.simplify(corrected - sp.Matrix([(m1 * l1 / 2 + m2 * r) * g * sp.cos(q1), m2 * g / 2 * sp.sin(q1)])) == sp.zeros(
        2, 1
    )


def test_corrected_equations_are_those_of_rp_arm_md():
    r = l1 + q2 / 2
    expected = sp.Matrix(
        [
            (m1 * l1**2 / 4 + Iz1 + m2 * r**2 + Iz2) * qdd1 + m2 * r * qd1 * qd2 + (m1 * l1 / 2 + m2 * r) * g * sp.cos(q1),
            m2 / 4 * qdd2 - m2 / 2 * r * qd1**2 + m2 * g / 2 * sp.sin(q1),
        ]
    )
    assert sp.simplify(lecture.derived().tau - expected) == sp.zeros(2, 1)


def test_printed_and_corrected_differ_exactly_in_gravity_and_coriolis():
    diff = difference(lecture.printed(), lecture.derived().tau)
    assert diff["M"] == sp.zeros(2, 1)
    assert diff["C"] != sp.zeros(2, 1) and diff["G"] != sp.zeros(2, 1)


def test_non_rigid_model_has_effective_slider_mass_m2_over_4_and_rigid_has_m2():
    """Erratum 3: the lecture's COM at l1 + q2/2 moves at half the joint speed."""
    assert sp.simplify(lecture.derived().M[1, 1] - m2 / 4) == 0
    rigid = lecture.rigid()
    assert sp.simplify(rigid.M[1, 1] - m2) == 0
    r2 = l1 + q2 + lecture.c2
    # With the rigid model the factor 2 of the Coriolis term is right.
    assert sp.simplify(rigid.C * sp.Matrix([qd1, qd2]) - sp.Matrix([2 * m2 * r2 * qd1 * qd2, -m2 * r2 * qd1**2])) == sp.zeros(
        2, 1
    )
    assert sp.simplify(rigid.G - sp.Matrix([(m1 * l1 / 2 + m2 * r2) * g * sp.cos(q1), m2 * g * sp.sin(q1)])) == sp.zeros(2, 1)


def test_every_erratum_is_named():
    assert set(lecture.ERRATA) == {1, 2, 3}
    assert {term for _, terms in lecture.ERRATA.values() for term in terms} == {"M", "C", "G"}


def test_unused_symbols_are_the_lectures():
    assert {str(s) for s in lecture.printed().free_symbols} == {
        "l1",
        "m1",
        "m2",
        "Iz1",
        "Iz2",
        "g",
        "q1",
        "q2",
        "qd1",
        "qd2",
        "qdd1",
        "qdd2",
    }
