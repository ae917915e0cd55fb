"""The excitation optimiser keeps its best feasible iterate and never calls its start an
optimum (issue 29, item 1)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize

import robodyn
from robodyn.cli import main
from robodyn.exceptions import RobodynWarning
from robodyn.ident import excitation as excitation_module
from robodyn.ident.excitation import ExcitationNotImprovedWarning, excite

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize(
    ("name", "duration"), [("mimic_arm.urdf", 4.0), pytest.param("rrp_arm.urdf", 10.0, marks=pytest.mark.slow)]
)
def test_an_optimiser_ending_outside_the_limits_still_returns_its_best_feasible_iterate(name, duration):
    # With 40 iterations SLSQP's last point breaks a limit on both arms (a mimic joint; a
    # prismatic one): the result used to fall back to the random start (rrp: 1.3e5), or
    # be a feasible last point worse than earlier ones (mimic: 5.9e6 from a 5.4e6 start).
    robot = robodyn.load(DATA / name)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExcitationNotImprovedWarning)
        result = excite(robot, iterations=40, duration=duration)
    assert result.improved
    assert result.condition < result.initial_condition / 100


def _fake_minimize(points, last):
    """SLSQP replaced by one that visits ``points(x0)`` and ends at ``last(x0)``."""

    def minimize(fun, x0, *, callback, **_options):
        for point in points(x0):
            callback(point)
        return scipy.optimize.OptimizeResult(x=last(x0), success=False)

    return minimize


def test_the_best_feasible_iterate_wins_over_an_infeasible_last_point(monkeypatch):
    robot = robodyn.load(DATA / "mimic_arm.urdf")
    real = scipy.optimize.minimize
    seen = []

    def minimize(fun, x0, *, callback, **options):
        def record(xk):
            seen.append(float(np.exp(fun(xk))))
            callback(xk)

        real(fun, x0, callback=record, **options)
        return scipy.optimize.OptimizeResult(x=x0 * 1e3, success=False)  # far outside every limit

    monkeypatch.setattr(excitation_module.scipy.optimize, "minimize", minimize)
    result = excite(robot, iterations=30, duration=4.0, harmonics=3)
    assert result.improved and result.condition < result.initial_condition / 100
    assert any(result.condition == pytest.approx(value) for value in seen)  # an iterate, not the far last point
    t = np.linspace(0, result.period, 400)
    assert np.all(np.abs(result.evaluate(t)[1]) <= result.velocity_limit)


def test_no_improvement_is_a_one_line_warning_and_the_text_never_calls_the_start_an_optimum(monkeypatch, tmp_path, capsys):
    robot = robodyn.load(DATA / "mimic_arm.urdf")
    outside = lambda x0: x0 * 1e3  # noqa: E731
    monkeypatch.setattr(excitation_module.scipy.optimize, "minimize", _fake_minimize(lambda x0: [], outside))
    with pytest.warns(ExcitationNotImprovedWarning) as caught:
        result = excite(robot, iterations=7, duration=4.0, harmonics=2)
    assert issubclass(ExcitationNotImprovedWarning, RobodynWarning)
    message = str(caught[0].message)
    assert "\n" not in message and "mimic_arm" in message and "7 iterations" in message
    assert not result.improved and result.condition == result.initial_condition
    out = tmp_path / "x.csv"
    code = main(["excite", str(DATA / "mimic_arm.urdf"), "--out", str(out), "--duration", "4", "--harmonics", "2"])
    captured = capsys.readouterr()
    assert code == 0 and out.is_file()  # the file is written: the start is within the limits
    assert "not optimised" in captured.out and "(start " not in captured.out
    warning_lines = [line for line in captured.err.splitlines() if "warning" in line]
    assert len(warning_lines) == 1 and "random start" in warning_lines[0]


def test_the_best_feasible_point_is_chosen_the_start_winning_ties():
    from robodyn.ident.excitation import _best_feasible

    start, better, outside, same, broken = (np.array(v, float) for v in ([1, 1], [2, 2], [9, 9], [2, 2], [np.nan, 3]))
    feasible = lambda x: bool(x[0] < 5)  # noqa: E731
    objective = lambda x: -float(np.sum(x))  # noqa: E731  (larger points are better)
    x, value = _best_feasible([start, better, outside, same, broken], feasible, objective)
    assert x is better and value == -4.0  # not the infeasible, better one; the first of two equals
    x, value = _best_feasible([start, outside], feasible, objective)
    assert x is start and value == -2.0
