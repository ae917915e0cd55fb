"""The what-if figure is scaled to its bars, with the effort limit as a line (issue 29, item 5)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from robodyn.viz.plots import text_overlaps, whatif_figure


def _rows(peaks):
    return [
        SimpleNamespace(material=m, payload=0.0, force=np.zeros(3), peak=np.array(p), rms=0.6 * np.array(p))
        for m, p in zip(("abs", "aluminium", "steel"), peaks, strict=True)
    ]


def test_bars_far_below_the_limit_fill_their_axis_and_the_limit_is_named():
    # a kuka-like sweep: 300 N m limits, peaks of 4 to 40 N m
    rows = _rows([[12.0, 4.0], [20.0, 6.0], [40.0, 9.0]])
    figure = whatif_figure(rows, ["a1", "a2"], ["N m", "N m"], effort_limits=[300.0, 300.0])
    for axis, top in zip(figure.axes[:2], (40.0, 9.0), strict=True):
        low, high = axis.get_ylim()
        assert low == 0.0 and top <= high <= 1.3 * top  # the tallest bar fills most of the axis
        assert any("limit 300 N m" in text.get_text() for text in axis.texts)
    legend = figure.legends[0]
    assert "effort limit" in [t.get_text() for t in legend.get_texts()]
    assert text_overlaps(figure) == []


def test_a_limit_near_the_bars_is_a_dashed_line_inside_the_axis():
    rows = _rows([[80.0], [90.0], [95.0]])
    figure = whatif_figure(rows, ["a1"], ["N m"], effort_limits=[100.0])
    axis = figure.axes[0]
    lines = [line for line in axis.get_lines() if line.get_linestyle() == "--" and len(line.get_ydata())]
    assert [float(line.get_ydata()[0]) for line in lines] == [100.0]
    assert axis.get_ylim()[1] > 100.0 and not axis.texts
