"""The coverage plots as one PNG (``scenegrep coverage --png FILE``), drawn with matplotlib.

The picture holds what the coverage page (:mod:`.coverage_page`) charts, in its colours
(:data:`.charts.BAR_COLOUR`, :data:`.style.GAP_COLOUR`): per axis (variable) a panel of bars,
the matches covering each bin (bar height = count), and a red stripe under every gap (a bin no
match covers); per pair of axes a heat map of the joint counts (empty cells white). The panel
titles give the covered bins, the ambiguous matches and those without a value, so a reader of
the picture alone sees that unknown values are neither coverage nor gaps. When part of the
data is unknown (:attr:`~scenegrep.dataset.coverage.Coverage.unknown`), the figure's title says so
and the uncovered bins' stripes are grey (uncovered in the data decided, not known gaps).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..dataset.coverage import AMBIGUOUS, NO_VALUE, Coverage
from ..writers.atomic import atomic_path
from .charts import BAR_COLOUR
from .style import GAP_COLOUR, UNKNOWN_COLOUR

PANEL_WIDTH = 6.4
"""Width (inches) of a panel; the picture is one panel wide, at 100 dpi."""

GAP_STRIPE = 0.04
"""A gap's stripe height as a fraction of the panel's tallest bar (of 1 when no bin is covered)."""


def coverage_figure(coverage: Coverage):
    """The matplotlib Figure (not attached to pyplot): one panel per axis, then one per pair.
    Bars are the panels' ``containers[0]`` (covered bins) and ``containers[1]`` (gap stripes)."""
    from matplotlib.colors import LinearSegmentedColormap
    from matplotlib.figure import Figure

    pairs = coverage.pairs()
    panels = max(len(coverage.axes) + len(pairs), 1)
    figure = Figure(figsize=(PANEL_WIDTH, 2.6 * panels), dpi=100, layout="constrained")
    plots = figure.subplots(panels, 1, squeeze=False)[:, 0]
    if coverage.unknown:
        figure.suptitle(f"unknown: {coverage.unknown}; grey bins: uncovered in the data decided", fontsize=8)
    stripes = UNKNOWN_COLOUR if coverage.unknown else GAP_COLOUR
    if not coverage.axes:
        plots[0].set_title("no random variable")
        plots[0].set_axis_off()
    for a, axis in enumerate(coverage.axes):
        counts = coverage.counts(a)
        column = coverage.assigned[:, a]
        bins = np.arange(axis.bins)
        stripe = GAP_STRIPE * max(int(counts.max(initial=0)), 1)
        covered = counts > 0
        plot = plots[a]
        plot.bar(bins[covered], counts[covered], width=0.9, color=BAR_COLOUR)
        plot.bar(bins[~covered], np.full(int((~covered).sum()), stripe), width=0.9, color=stripes)
        plot.set_title(
            f"{axis.name}: {int(covered.sum())} of {axis.bins} bins covered, "
            f"{int((column == AMBIGUOUS).sum())} ambiguous, {int((column == NO_VALUE).sum())} without a value",
            fontsize=8,
            loc="left",
        )
        ticks = bins[:: max(1, axis.bins // 6)]
        plot.set_xticks(ticks, [axis.label(int(k)) for k in ticks], fontsize=7)
        plot.set_xlim(-0.5, axis.bins - 0.5)
        plot.set_ylabel("matches", fontsize=8)
    shades = LinearSegmentedColormap.from_list("coverage", ["#ffffff", BAR_COLOUR])
    for plot, (a, b) in zip(plots[len(coverage.axes) :], pairs):
        cells = coverage.joint(a, b)
        plot.imshow(cells, cmap=shades, vmin=0, vmax=max(int(cells.max(initial=0)), 1), aspect="auto")
        first, second = coverage.axes[a], coverage.axes[b]
        plot.set_title(
            f"{first.name} × {second.name}: {int((cells > 0).sum())} of {cells.size} cells", fontsize=8, loc="left"
        )
        plot.set_xlabel(second.name, fontsize=7)
        plot.set_ylabel(first.name, fontsize=7)
    return figure


def write_coverage_png(coverage: Coverage, path: str | Path) -> None:
    """Write :func:`coverage_figure` as a PNG file (atomically)."""
    with atomic_path(Path(path)) as tmp:
        coverage_figure(coverage).savefig(tmp, format="png")
