"""The OSC's damped task inertia where the damping binds and where it is slack.

``Λ = U diag(s / (s² + λ²)) Uᵀ`` with ``λ = damping · max(s)``: each damped eigenvalue is at
most ``1 / 2λ``, reached exactly where ``s = λ`` (the binding case: a direction as weak as
the damping), and within a relative ``(λ / s)²`` of the plain ``1 / s`` where ``s ≫ λ``
(slack). Checked on matrices built from chosen eigenvalues in a random 3-D basis.
"""

from __future__ import annotations

import numpy as np

from robodyn.sim.operational_space import damped_task_inertia


def built(values: list[float], seed: int = 39) -> tuple[np.ndarray, np.ndarray]:
    basis, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(len(values), len(values))))
    return basis @ np.diag(values) @ basis.T, basis


def test_the_damping_binds_exactly_where_a_direction_is_as_weak_as_it():
    damping, largest = 1e-2, 4.0
    weak = damping * largest  # s = λ: the damped value is its bound 1 / 2λ
    inverse, basis = built([weak, 0.5, largest])
    inertia = damped_task_inertia(inverse, damping)
    along = basis[:, 0] @ inertia @ basis[:, 0]
    assert abs(along - 1 / (2 * weak)) < 1e-12 * along
    assert np.linalg.eigvalsh(inertia)[-1] <= 1 / (2 * weak) * (1 + 1e-12)
    # Weaker still (s = λ / 10): below the bound, where the plain inverse is 10 / λ.
    inverse, basis = built([weak / 10, 0.5, largest])
    along = basis[:, 0] @ damped_task_inertia(inverse, damping) @ basis[:, 0]
    assert along < 1 / (2 * weak) and abs(along - (weak / 10) / ((weak / 10) ** 2 + weak**2)) < 1e-12 * along


def test_the_damping_is_slack_where_every_direction_is_strong():
    damping, values = 1e-3, [0.8, 1.5, 4.0]
    inverse, _ = built(values)
    plain = np.linalg.inv(inverse)
    damped = damped_task_inertia(inverse, damping)
    bound = (damping * max(values) / min(values)) ** 2  # relative change of the weakest direction
    assert np.abs(damped - plain).max() <= bound * np.abs(plain).max()
    assert np.abs(damped - plain).max() > 0.1 * bound * np.abs(plain).max() / max(values)  # it does act a little
    np.testing.assert_allclose(damped_task_inertia(inverse, 0.0), plain, rtol=1e-12, atol=1e-14)
