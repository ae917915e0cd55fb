"""The contact problem's solver: the polish's exact modes against Pinocchio's ADMM, and
redundant contact sets (more rows than the robot has degrees of freedom) solved at once."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robodyn
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.contact_solver import ContactSettings, polish, solve_impulses
from robodyn.sim.ground import Ground

DATA = Path(__file__).parents[1] / "data" / "contact"


def _problem(rng, contacts, nv=9):
    jacobian = rng.normal(size=(3 * contacts, nv))
    root = rng.normal(size=(nv, nv))
    mass = root @ root.T + nv * np.eye(nv)
    delassus = jacobian @ np.linalg.solve(mass, jacobian.T)
    return 0.5 * (delassus + delassus.T), rng.normal(size=3 * contacts)


def test_the_polished_modes_are_admms_answer_made_exact_and_a_wrong_guess_is_refused():
    """Random cone problems of 1–3 contacts (open, sticking and slipping ones): the polish of
    ADMM's answer is within ADMM's tolerance of it; the zero guess of a problem whose answer
    pushes is refused (not a solution)."""
    rng, settings, seen = np.random.default_rng(11), ContactSettings(tolerance=1e-12, max_iterations=5000), 0
    for _ in range(40):
        delassus, velocity = _problem(rng, int(rng.integers(1, 4)))
        impulses, _, converged = solve_impulses(
            delassus, velocity, 0.4, ContactSettings(polish=False, tolerance=1e-12, max_iterations=5000)
        )
        if not converged:
            continue
        polished = polish(delassus, velocity, 0.4, impulses)
        assert polished is not None
        assert np.abs(polished - impulses).max() < 1e-6 * max(1.0, float(np.abs(impulses).max()))
        seen += 1
        if impulses.reshape(-1, 3)[:, 2].max() > 1e-3:
            assert polish(delassus, velocity, 0.4, np.zeros_like(impulses)) is None
        assert solve_impulses(delassus, velocity, 0.4, settings, polished)[1] == 0  # kept: no ADMM
    assert seen >= 30


def test_a_box_thrown_tumbling_lands_with_every_step_solved_exactly():
    """Landing on an edge, then a face: 6 or 12 rows of a 6-dof body are redundant, solved
    least-norm at once (before: an LU solve of the singular rows was tried first; 6 steps
    ended at ADMM's iteration limit, the rest's total force 3e-9 off m g)."""
    box = robodyn.load(DATA / "box.urdf", floating_base=True)
    q0 = box.neutral_configuration()
    q0[2] = 0.15
    run = simulate_contact(box, ground=Ground(friction=0.5), duration=0.6, q0=q0, v0=np.array([0.5, 0, 0, 1.0, 2.0, 0.5]))
    assert run.converged.all()
    assert (run.iterations > 0).sum() <= 8  # 5 measured (11 before)
    assert abs(run.normal_forces[-1].sum() / (2.5 * 9.81) - 1) < 1e-12
