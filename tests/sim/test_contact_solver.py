"""The contact problem's solver: the polish's exact modes against Pinocchio's ADMM, and
redundant contact sets (more rows than the robot has degrees of freedom) solved at once."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robodyn
from robodyn.sim.contact import contact_kinematics, contact_step
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.contact_solver import ContactSettings, polish, solve_impulses
from robodyn.sim.ground import ContactPoint, Ground

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


def test_solo12_standing_while_its_joints_move_keeps_its_modes_without_admm():
    """A PD moving the legs 0.02 rad from a 1 mm landing: the feet stick throughout. The
    velocities of last step's impulses move them (the joints accelerate), which read as
    slips sent every step to ADMM (100–300 iterations); their impulses inside the cones
    keep them sticking."""
    robot = robodyn.load("solo12")
    feet = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
    points = tuple(ContactPoint(foot, foot, (0.0, 0.0, 0.0), 1e-4) for foot in feet)
    q0 = robot.neutral_configuration()
    q0[2] -= contact_kinematics(robot, q0, Ground(), points)[0].min() - 1e-3
    target = q0[7:] + 0.02

    def hold(t, q, v):
        return np.r_[np.zeros(6), 5.0 * (target - q[7:]) - 0.1 * v[6:]]

    run = simulate_contact(robot, ground=Ground(friction=0.8), contacts=points, controller=hold, duration=0.1, q0=q0)
    assert run.active[20:].all() and run.slip[20:].max() < 1e-12  # standing, sticking
    assert (run.iterations[20:] == 0).all()  # its modes kept at every step
    assert run.converged.all()


def test_impulses_on_their_cones_are_not_read_as_sticking():
    """The negative control of the cone reading: a contact pushed along its plane slips
    (its impulse on the cone); ``cone=True`` declines it, the velocities' reading keeps it."""
    delassus, velocity = np.eye(3), np.array([1.0, 0.0, -1.0])  # pushed along t₁ and into the plane
    impulses = solve_impulses(delassus, velocity, 0.4, ContactSettings())[0]
    assert abs(np.hypot(*impulses[:2]) - 0.4 * impulses[2]) < 1e-12  # on the cone: slipping
    assert polish(delassus, velocity, 0.4, impulses, cone=True) is None
    assert polish(delassus, velocity, 0.4, impulses) is not None


def test_a_step_without_contact_points_is_free_motion():
    """No rows at all (Pinocchio's ADMM crashed the process on them): the free step."""
    box = robodyn.load(DATA / "box.urdf", floating_base=True)
    q, v = box.neutral_configuration(), np.zeros(box.nv)
    step = contact_step(box, q, v, np.zeros(box.nv), 1e-3, Ground(), ())
    assert step.forces.shape == (0, 3) and step.iterations == 0 and step.converged
    assert abs(step.v[2] + 9.81e-3) < 1e-15 and np.abs(np.delete(step.v, 2)).max() < 1e-15  # g dt, down
