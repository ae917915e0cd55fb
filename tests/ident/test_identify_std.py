"""The least-squares standard deviations of identify(method="ls"), exactly.

A |z| < 3 band cannot see a small bias in the standard deviations. Two exact checks do:

- the unbiased formula, written here from the base regressor ``W`` (m rows, r columns) and
  the residual of the fit: ``σ̂² = |y − W β̂|² / (m − r)``, ``cov = σ̂² (WᵀW)⁻¹``;
- the spread over repeated noisy runs, made exact: the m runs whose noise vectors are the
  columns of an orthogonal matrix times ``σ √m`` have the second moment ``σ² I`` exactly,
  so over them the mean square error of each estimate is exactly ``σ² diag((WᵀW)⁻¹)`` and
  the mean of the reported variances (unbiased: ``E σ̂² = σ²``) must equal it to round-off.

The robot is the oblique test robot (3-D: oblique non-unit axes, a prismatic joint, 21
base parameters) on 30 random states: m = 120 rows, so ``m`` for ``m − r`` is a 10 % bias.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.ident import base_parameters, identify
from robodyn.ident.base import random_states
from robodyn.trajectory import Trajectory
from tests.conftest import ROOT

SAMPLES = 30


@pytest.fixture(scope="module")
def oblique():
    robot = robodyn.load(ROOT / "tests" / "data" / "robots" / "oblique.urdf")
    base = base_parameters(robot)
    q, v, a = random_states(robot, SAMPLES, np.random.default_rng(39))
    tau = robot.inverse_dynamics(q, v, a)
    data = Trajectory(np.arange(float(SAMPLES)), q, v, a, tau, list(robot.joint_names), robot.name)
    w = base.regressor(q, v, a).reshape(-1, len(base.names))
    assert np.abs(w @ base.values - tau.reshape(-1)).max() < 1e-9 * np.abs(tau).max()  # W is the model's regressor
    return robot, base, data, w


def test_the_ls_standard_deviations_are_the_unbiased_formula(oblique):
    robot, base, data, w = oblique
    m, r = w.shape
    noise = np.random.default_rng(1).normal(size=data.tau.shape) * 0.02
    result = identify(robot, data, data.tau + noise, base=base)
    y = (data.tau + noise).reshape(-1)
    beta, *_ = np.linalg.lstsq(w, y, rcond=None)
    variance = np.sum((y - w @ beta) ** 2) / (m - r)
    expected = np.sqrt(variance * np.diag(np.linalg.inv(w.T @ w)))
    np.testing.assert_allclose(result.values, beta, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(result.std, expected, rtol=1e-8)
    np.testing.assert_allclose(result.covariance, variance * np.linalg.inv(w.T @ w), rtol=1e-7, atol=1e-14)
    # Negative control: the biased σ̂² (m instead of m − r) is 10 % off: the tolerance sees 0.01 %.
    assert np.abs(np.sqrt(variance * (m - r) / m * np.diag(np.linalg.inv(w.T @ w))) / result.std - 1).min() > 0.05


def test_the_ls_standard_deviations_are_the_spread_over_repeated_noisy_runs(oblique):
    robot, base, data, w = oblique
    m = w.shape[0]
    sigma = 0.03
    basis, _ = np.linalg.qr(np.random.default_rng(2).normal(size=(m, m)))
    errors, variances = [], []
    for column in basis.T:  # m runs: noise of second moment σ² I exactly
        noise = (sigma * np.sqrt(m) * column).reshape(data.tau.shape)
        result = identify(robot, data, data.tau + noise, base=base)
        errors.append(result.values - base.values)
        variances.append(result.std**2)
    spread = np.mean(np.square(errors), axis=0)  # the runs' mean square error of each parameter
    reported = np.mean(variances, axis=0)
    np.testing.assert_allclose(reported, spread, rtol=1e-6)  # a 0.75 % bias in std is 1.5 % here
    # And the spread is the noise's: σ² diag((WᵀW)⁻¹) (the check above is not vacuous).
    np.testing.assert_allclose(spread, sigma**2 * np.diag(np.linalg.inv(w.T @ w)), rtol=1e-6)
