"""The contact problem's solver: the polish's exact modes against Pinocchio's ADMM, and
redundant contact sets (more rows than the robot has degrees of freedom) solved at once."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim import contact_solver
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


def _modes(delassus, velocity, friction, impulses):
    """Each contact's mode: open, sticking or slipping (by its impulse and velocity)."""
    u = (delassus @ impulses + velocity).reshape(-1, 3)
    p, scale = impulses.reshape(-1, 3), np.abs(impulses).max()
    return [
        "open" if pi[2] <= 1e-6 * scale else "slipping" if np.hypot(*ui[:2]) > 1e-6 * np.abs(velocity).max() else "sticking"
        for pi, ui in zip(p, u, strict=True)
    ]


def test_the_polish_is_the_same_at_any_scale_of_the_impulses():
    """The problem is homogeneous: the free velocity ``s c`` has the impulses ``s p`` (the
    cones are cones). The polish of random problems (open, sticking and slipping contacts) at
    ``s`` = 1e-9 (a gram on a microsecond step) and 1e3 is ``s`` times its polish at 1
    (before: the modes read against absolute floors would call a nanonewton-second contact
    open, a nanometre-a-second slip sticking). Negative control: the zero impulses of a
    problem whose contacts push are refused at every scale."""
    rng, tight, seen = np.random.default_rng(3), ContactSettings(polish=False, tolerance=1e-12, max_iterations=5000), set()
    for _ in range(25):
        delassus, velocity = _problem(rng, 3)
        impulses, _, converged = solve_impulses(delassus, velocity, 0.4, tight)
        if not converged:
            continue
        exact = polish(delassus, velocity, 0.4, impulses)
        assert exact is not None
        modes = _modes(delassus, velocity, 0.4, exact)
        seen.update(modes)
        for scale in (1e-9, 1e3):
            scaled = polish(delassus, scale * velocity, 0.4, scale * impulses)
            assert scaled is not None
            assert np.abs(scaled - scale * exact).max() <= 1e-9 * scale * np.abs(exact).max()
            if "open" not in set(modes) or len(set(modes)) > 1:
                assert polish(delassus, scale * velocity, 0.4, np.zeros(9)) is None  # negative control
    assert seen == {"open", "sticking", "slipping"}


def test_a_guess_inside_its_cone_is_read_as_sticking_whatever_its_direction():
    """``cone=True`` (the previous step's impulses): a guess strictly inside its cone keeps
    the contact sticking, and the answer is the sticking impulse (``u = A p + c = 0``, ``p``
    inside the cone); a guess on the cone's boundary (it slipped) is declined. The reading is
    the same for every direction in the contact plane (t₁, t₂ and between)."""
    delassus, friction = _problem(np.random.default_rng(8), 1)[0], 1.0  # (μ = 1: no special value)
    sticking = np.array([0.2 * np.cos(1.0), 0.2 * np.sin(1.0), 2.0])  # inside its cone
    velocity = -delassus @ sticking
    for angle in np.linspace(0.0, 2 * np.pi, 8, endpoint=False):
        direction = friction * 2.0 * np.array([np.cos(angle), np.sin(angle)])  # on the cone's boundary
        inside = polish(delassus, velocity, friction, np.r_[0.9 * direction, 2.0], cone=True)
        assert inside is not None and np.abs(inside - sticking).max() < 1e-12
        assert np.abs(delassus @ inside + velocity).max() < 1e-12
        assert polish(delassus, velocity, friction, np.r_[direction, 2.0], cone=True) is None  # slipped: declined


@pytest.mark.parametrize("scale", [1.0, 1e-9])
def test_a_contact_slipping_by_nanometres_a_second_on_its_cone_is_read_as_slipping(scale):
    """One contact open (lifting at 1 m/s: the velocities' scale), the other slipping at
    1e-8 m/s in a direction between t₁ and t₂ with its impulse on its cone: the polish of
    that answer keeps it, the friction ``−μ p_n s`` against the slip and ``u_n = 0``. Read
    against the open contact's scale alone (1e-6 of it), the slip would be sticking, an
    impulse outside its cone (refused). The same problem scaled by 1e-9 is read the same.
    Negative control: as a previous step's impulses (``cone=True``) the same answer is
    declined (on the cone: it slipped)."""
    delassus, friction = _problem(np.random.default_rng(4), 2)[0], 0.6
    slip = 1e-8 * np.array([np.cos(0.7), np.sin(0.7)])
    answer = np.r_[0.0, 0.0, 0.0, -friction * 1.5 * slip / np.linalg.norm(slip), 1.5]
    velocity = scale * (np.r_[0.0, 0.0, 1.0, slip, 0.0] - delassus @ answer)
    polished = polish(delassus, velocity, friction, scale * answer)
    assert polished is not None and np.abs(polished - scale * answer).max() < 1e-9 * scale  # (s read from u: c's rounding)
    after, friction_force = delassus @ polished + velocity, polished[3:5]
    assert abs(np.linalg.norm(friction_force) - friction * polished[5]) < 1e-12 * scale  # on the cone
    assert friction_force @ after[3:5] / np.linalg.norm(friction_force) / np.linalg.norm(after[3:5]) < -0.99  # against s
    assert abs(after[5]) < 1e-12 * scale and np.linalg.norm(after[3:5]) > 0.5e-8 * scale  # sliding on, u_n = 0
    assert polish(delassus, velocity, friction, scale * answer, cone=True) is None


def test_a_box_resting_on_four_corners_shares_its_weight_equally_the_least_norm_impulses():
    """A rigid box (6 dof, 12 rows: a redundant set) on its four corners, the step's free
    velocity ``g dt`` down: every corner sticks, and of the impulses that hold the box
    (``v⁺ = 0``) the least-norm ones (the constraints layer's rule) are the symmetric
    shares ``m g dt / 4`` each, no friction. Negative control: an unequal split holds the
    box too (the same ``v⁺ = 0``): only the rule, not the motion, tells them apart."""
    mass, dt, g = 2.5, 1e-3, 9.81
    corners = [np.array([x, y, -0.05]) for x in (-0.2, 0.2) for y in (-0.1, 0.1)]  # below the centre of mass
    inertia = np.diag([0.01, 0.035, 0.042])
    jacobian = np.vstack(
        [np.hstack([np.eye(3), -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])]) for r in corners]
    )
    inverse = np.linalg.inv(np.block([[mass * np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), inertia]]))
    delassus, free = jacobian @ inverse @ jacobian.T, np.r_[0.0, 0.0, -g * dt, 0.0, 0.0, 0.0]
    velocity, shares = jacobian @ free, np.tile([0.0, 0.0, mass * g * dt / 4], 4)
    for guess, cone in ((1.1 * shares, True), (solve_impulses(delassus, velocity, 0.5, ContactSettings(polish=False))[0], False)):
        impulses = polish(delassus, velocity, 0.5, guess, dofs=6, cone=cone)
        assert impulses is not None and np.abs(impulses - shares).max() < 1e-12 * mass * g * dt
        assert np.abs(free + inverse @ jacobian.T @ impulses).max() < 1e-15  # held: v⁺ = 0
    unequal = shares * np.tile([1.2, 0.8, 0.8, 1.2], (3, 1)).T.ravel()  # diagonal corners carry more
    assert np.abs(free + inverse @ jacobian.T @ unequal).max() < 1e-15  # it holds the box too


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e3])
def test_the_polishs_check_accepts_the_problems_solutions_and_refuses_each_broken_condition(scale):
    """The check a polished answer passes (``_solves``) is the cone complementarity problem
    itself, at every scale of the impulses: a sticking impulse inside its cone, a slip on
    the cone continuing along its direction (along t₁ or t₂)
    and an open contact separating are accepted; each broken by 1e-6 of its scale is
    refused — outside the cone along t₁ or t₂, a pull, a penetration, an open contact that
    pushes while separating, a slip that turned back."""
    delassus, friction = _problem(np.random.default_rng(6), 1)[0], 0.5

    def check(impulses, velocity_after, before=None):
        impulses, after = scale * np.asarray(impulses, float), scale * np.asarray(velocity_after, float)
        velocity = after - delassus @ impulses
        return contact_solver._solves(
            delassus, velocity, friction, impulses, list(after if before is None else scale * np.asarray(before))
        )

    assert check([0.1, 0.2, 1.0], [0.0, 0.0, 0.0])  # sticking
    assert check([0.0, -0.5, 1.0], [0.0, 0.3, 0.0])  # slipping along t₂, friction μ p_n against it
    assert check([-0.5, 0.0, 1.0], [0.3, 0.0, 0.0])  # along t₁
    assert check([0.0, 0.0, 0.0], [0.2, -0.1, 0.4])  # open, separating
    assert not check([0.5 + 1e-6, 0.0, 1.0], [0.0, 0.0, 0.0])  # outside the cone along t₁
    assert not check([0.0, 0.5 + 1e-6, 1.0], [0.0, 0.0, 0.0])  # along t₂
    assert not check([0.0, 0.0, -1e-6], [0.0, 0.0, 1.0])  # a pull
    assert not check([0.0, 0.0, 0.0], [0.0, 0.0, -1e-6])  # penetrating
    assert not check([0.0, 0.0, 1.0], [0.0, 0.0, 0.5])  # pushing while separating
    assert not check([0.0, -0.5, 1.0], [0.0, 0.3, 0.0], before=[0.0, -0.3, 0.0])  # the slip turned back
    assert not check([-0.5, 0.0, 1.0], [0.3, 0.0, 0.0], before=[-0.3, 0.0, 0.0])  # along t₁


@pytest.mark.parametrize(
    ("field", "value", "sentence"),
    [
        ("baumgarte", 0.0, "baumgarte must be a fraction in (0, 1], got 0.0."),
        ("baumgarte", 1.0 + 1e-12, "baumgarte must be a fraction in (0, 1], got 1.000000000001."),
        ("baumgarte", "0.5", "baumgarte must be a fraction in (0, 1], got '0.5'."),
        ("tolerance", 0.0, "tolerance must be a finite tolerance > 0, got 0.0."),
        ("tolerance", float("inf"), "tolerance must be a finite tolerance > 0, got inf."),
        ("tolerance", "1e-9", "tolerance must be a finite tolerance > 0, got '1e-9'."),
        ("max_iterations", 0, "max_iterations must be an integer > 0, got 0."),
        ("max_iterations", 10.0, "max_iterations must be an integer > 0, got 10.0."),
    ],
)
def test_each_setting_out_of_its_range_is_refused_in_one_sentence_and_its_bounds_are_accepted(field, value, sentence):
    with pytest.raises(InputError) as caught:
        ContactSettings(**{field: value})
    assert str(caught.value) == sentence and caught.value.argument == field
    assert ContactSettings(baumgarte=1, tolerance=1e-300, max_iterations=1).baumgarte == 1  # the bounds: accepted


def test_last_steps_sticking_impulses_keep_their_modes_without_admm_when_the_problem_changed():
    """Two feet sticking last step; this step the free velocity changed (the joints moved):
    last step's impulses, inside their cones, keep both feet sticking — the answer is this
    step's sticking impulses (``u = A p + c = 0``, inside the cones) with no ADMM iteration.
    Read by their velocities instead, the feet would slip (the change moves them): ADMM
    would run (the negative control: ``cone=False``'s reading alone declines them)."""
    delassus, friction = _problem(np.random.default_rng(12), 2)[0], 0.8
    sticking = np.array([0.1, -0.05, 1.0, -0.08, 0.12, 0.7])  # this step's, inside the cones
    velocity = -delassus @ sticking
    previous = sticking + np.array([0.15, 0.1, 0.2, 0.1, -0.2, -0.1])  # last step's, inside the cones too
    impulses, iterations, converged = solve_impulses(delassus, velocity, friction, ContactSettings(), previous)
    assert iterations == 0 and converged
    assert np.abs(impulses - sticking).max() < 1e-12 and np.abs(delassus @ impulses + velocity).max() < 1e-12
    assert polish(delassus, velocity, friction, previous) is None  # the velocities' reading: slipping


def _residual(delassus, velocity, friction, impulses):
    """The cone complementarity problem's largest violation: ``|p · û|``, the cone, ``u_n < 0``."""
    u, worst = delassus @ impulses + velocity, 0.0
    for p, ui in zip(impulses.reshape(-1, 3), u.reshape(-1, 3), strict=True):
        desaxce = ui + np.array([0.0, 0.0, friction * np.hypot(*ui[:2])])
        worst = max(worst, abs(p @ desaxce), np.hypot(*p[:2]) - friction * p[2], -ui[2])
    return worst


def test_admms_loose_answer_is_polished_exact_and_left_as_it_is_without_the_polish():
    """Two contacts sticking and one lifting off (an answer built first, its free velocity
    from it); ADMM stopped at a loose tolerance (1e-7): polished, the answer is the built
    one to round-off; with ``polish=False`` it is ADMM's own, off by about its tolerance
    (the negative control: the residual sees the difference)."""
    delassus, friction = _problem(np.random.default_rng(21), 3)[0], 0.8
    answer = np.array([0.2, -0.1, 1.0, -0.3, 0.25, 0.9, 0.0, 0.0, 0.0])  # inside the cones, the last open
    velocity = np.r_[np.zeros(6), 0.3, -0.2, 0.5] - delassus @ answer
    exact, iterations, converged = solve_impulses(delassus, velocity, friction, ContactSettings(tolerance=1e-7))
    assert converged and iterations > 0 and np.abs(exact - answer).max() < 1e-12
    assert _residual(delassus, velocity, friction, exact) < 1e-12
    raw = solve_impulses(delassus, velocity, friction, ContactSettings(tolerance=1e-7, polish=False))[0]
    assert 1e-9 < _residual(delassus, velocity, friction, raw) < 1e-2
