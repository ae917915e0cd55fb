"""The layout check of a figure: text that collides or leaves the figure.

:func:`text_overlaps` draws a :class:`matplotlib.figure.Figure` on an Agg canvas and lists
every pair of texts or legends whose boxes intersect, every legend over a plot and every
text cut off by the figure's edge. The tests run it on every figure of
:mod:`robodyn.viz.plots`; :func:`robodyn.viz.plots.whatif_figure` uses it to tilt crowded
tick labels.
"""

from __future__ import annotations

from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox


def _visible_ticks(axis) -> list:
    low, high = sorted(axis.get_view_interval())
    tolerance = 1e-9 * (high - low)
    locations = axis.get_majorticklocs()
    labels = []
    for tick, location in zip(axis.get_major_ticks(len(locations)), locations, strict=True):
        if low - tolerance <= location <= high + tolerance:
            labels += [label for label in (tick.label1, tick.label2) if label.get_visible() and label.get_text()]
    return labels


def text_boxes(figure: Figure) -> list[tuple[str, Bbox]]:
    """Every visible text and legend of a figure with its box in display pixels (draws it).

    Args:
        figure: The figure.
    """
    canvas = figure.canvas if isinstance(figure.canvas, FigureCanvasAgg) else FigureCanvasAgg(figure)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes: list[tuple[str, Artist]] = []
    for number, axis in enumerate(figure.axes):
        if not axis.get_visible():
            continue
        texts = [
            ("title", axis.title),
            ("xlabel", axis.xaxis.label),
            ("ylabel", axis.yaxis.label),
            ("x offset", axis.xaxis.get_offset_text()),
            ("y offset", axis.yaxis.get_offset_text()),
            *(("text", text) for text in axis.texts),
        ]
        texts += [("x tick", label) for label in _visible_ticks(axis.xaxis)]
        texts += [("y tick", label) for label in _visible_ticks(axis.yaxis)]
        boxes += [(f"axes {number} {kind} {artist.get_text()!r}", artist) for kind, artist in texts]
        legend = axis.get_legend()
        if legend is not None:
            boxes.append((f"axes {number} legend", legend))
    boxes += [(f"figure legend {i}", legend) for i, legend in enumerate(figure.legends)]
    # Figure._suptitle (private, not in the stubs) is the Text that suptitle() made
    suptitle: Text | None = getattr(figure, "_suptitle", None)
    boxes += [(f"figure text {text.get_text()!r}", text) for text in figure.texts if text is not suptitle]
    if suptitle is not None:
        boxes.append((f"suptitle {suptitle.get_text()!r}", suptitle))
    found = []
    for name, artist in boxes:
        if artist.get_visible() and (not hasattr(artist, "get_text") or artist.get_text()):
            found.append((name, artist.get_window_extent(renderer)))
    return found


def text_overlaps(figure: Figure, *, tolerance: float = 0.5) -> list[tuple[str, str]]:
    """Pairs of texts/legends whose boxes intersect, legends over a plot, text cut off.

    Args:
        figure: The figure (it is drawn to measure).
        tolerance: Overlap in [pixel] forgiven on each side.

    Returns:
        ``(a, b)`` descriptions of each problem; empty for a clean layout.
    """
    boxes = text_boxes(figure)
    problems = []
    for i, (name_a, a) in enumerate(boxes):
        shrunk = Bbox.from_extents(a.x0 + tolerance, a.y0 + tolerance, a.x1 - tolerance, a.y1 - tolerance)
        for name_b, b in boxes[i + 1 :]:
            if shrunk.overlaps(b):
                problems.append((name_a, name_b))
        if a.x0 < -tolerance or a.y0 < -tolerance or a.x1 > figure.bbox.x1 + tolerance or a.y1 > figure.bbox.y1 + tolerance:
            problems.append((name_a, "the figure's edge"))
    for name, box in boxes:
        if "legend" in name:
            for number, axis in enumerate(figure.axes):
                if box.overlaps(axis.get_window_extent()):
                    problems.append((name, f"axes {number} data"))
    return problems
