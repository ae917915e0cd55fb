"""What a simulation run on the ground may ask, checked when its plan is made.

The contact step (:mod:`robodyn.sim.contact`) is semi-implicit Euler at the velocity level
with the controller sampled once a step; it has no momentum observer and does not enforce
joint limits. A plan asking for those with a ground is refused, naming the parameter.
"""

from __future__ import annotations

from collections.abc import Sequence

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.ground import ContactPoint, Contacts, Ground, contact_points


def check_contact_run(
    robot: Robot,
    ground: Ground | None,
    contacts: str | Sequence[str | ContactPoint],
    *,
    integrator: str,
    every: int | None,
    limits: str,
    observer: object,
) -> Contacts | None:
    """The contact points of a run on ``ground`` (``None`` without one), or an
    :class:`InputError` naming what a contact run does not do."""
    if ground is None:
        if not (isinstance(contacts, str) and contacts == "collision"):
            raise InputError("contacts", "given only with a ground", repr(contacts)[:80])
        return None
    if not isinstance(ground, Ground):
        raise InputError("ground", "a robodyn.sim.ground.Ground (a plane, its normal and friction)", repr(ground)[:80])
    refusals = [
        (integrator != "semi-implicit-euler", "integrator", "'semi-implicit-euler' with a ground (the contact step's scheme)", repr(integrator)),
        (every not in (None, 1), "control_period", "the step dt with a ground (the contact step samples the controller each step)", f"{every} steps"),
        (limits == "enforce", "limits", "'warn' or 'ignore' with a ground (the contact step does not enforce limits)", repr(limits)),
        (observer is not None, "observer", "none with a ground (the contact step runs no observer)", "an observer"),
    ]  # fmt: skip
    for refused, name, expected, received in refusals:
        if refused:
            raise InputError(name, expected, received)
    return contact_points(robot, contacts)


__all__ = ["check_contact_run"]
