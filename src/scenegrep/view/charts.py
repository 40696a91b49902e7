"""Small SVG charts for the report page: drawn here, so the page needs no script library or network."""

from __future__ import annotations

import html
from collections.abc import Sequence

import numpy as np

from .style import CHART_COLOURS, GAP_COLOUR

BAR_COLOUR = CHART_COLOURS[0]


def bar_chart(
    labels: Sequence[str], series: Sequence[Sequence[float]], names: Sequence[str], title: str, chart_id: str
) -> str:
    """Horizontal bars, one group per label and one bar per series (each with its legend name)."""
    colours = CHART_COLOURS
    row, bar, left, width = 22, 16 / max(len(series), 1), 190, 520
    top = 34 + 18 * (len(series) > 1)
    height = top + row * len(labels) + 10
    most = max((max(s, default=0) for s in series), default=0) or 1
    parts = [_title(title)]
    for k, name in enumerate(names if len(series) > 1 else ()):
        parts.append(f'<rect x="{left + 150 * k}" y="28" width="10" height="10" fill="{colours[k]}"/>')
        parts.append(f'<text x="{left + 150 * k + 14}" y="37" class="legend">{html.escape(name)}</text>')
    for i, label in enumerate(labels):
        y = top + row * i
        parts.append(f'<text x="{left - 6}" y="{y + 13}" text-anchor="end">{html.escape(_short(label))}</text>')
        for k, values in enumerate(series):
            w = width * values[i] / most
            parts.append(
                f'<rect x="{left}" y="{y + 2 + bar * k:.1f}" width="{w:.1f}" height="{bar - 1:.1f}" '
                f'fill="{colours[k]}">'
                f"<title>{html.escape(label)}: {_number(values[i])}</title></rect>"
            )
            parts.append(f'<text x="{left + w + 4:.1f}" y="{y + bar * (k + 1) - 1:.1f}">{_number(values[i])}</text>')
    return _svg(chart_id, left + width + 60, height, parts)


def histogram(values: Sequence[float], title: str, unit: str, chart_id: str, bins: int = 12) -> str:
    """A histogram of ``values`` (in ``unit``)."""
    counts, edges = np.histogram(np.asarray(values, dtype=float), bins=bins) if len(values) else ([], [0.0])
    left, width, plot_height, top = 40, 620, 150, 34
    most = max(counts, default=0) or 1
    parts = [_title(title)]
    step = width / max(len(counts), 1)
    for k, count in enumerate(counts):
        h = plot_height * count / most
        parts.append(
            f'<rect x="{left + k * step:.1f}" y="{top + plot_height - h:.1f}" width="{step - 2:.1f}" height="{h:.1f}" '
            f'fill="{BAR_COLOUR}"><title>{edges[k]:.2f}-{edges[k + 1]:.2f} {unit}: {count}</title></rect>'
        )
        if count:
            parts.append(
                f'<text x="{left + (k + 0.5) * step:.1f}" y="{top + plot_height - h - 3:.1f}" '
                f'text-anchor="middle">{count}</text>'
            )
    for k in range(0, len(edges), max(1, len(edges) // 6)):
        parts.append(
            f'<text x="{left + k * step:.1f}" y="{top + plot_height + 16}" text-anchor="middle">{edges[k]:.3g}</text>'
        )
    parts.append(f'<text x="{left + width / 2}" y="{top + plot_height + 34}" text-anchor="middle">{unit}</text>')
    return _svg(chart_id, left + width + 20, top + plot_height + 42, parts)


def _svg(chart_id: str, width: float, height: float, parts: list[str]) -> str:
    return (
        f'<svg id="{chart_id}" class="chart" viewBox="0 0 {width:.0f} {height:.0f}" width="{width:.0f}" '
        f'height="{height:.0f}" xmlns="http://www.w3.org/2000/svg" role="img">' + "".join(parts) + "</svg>"
    )


def _title(text: str) -> str:
    return f'<text x="4" y="18" class="title">{html.escape(text)}</text>'


def _short(label: str, most: int = 28) -> str:
    return label if len(label) <= most else label[: most - 1] + "…"


def _number(value: float) -> str:
    return f"{value:g}" if float(value) != int(value) else str(int(value))


def bin_chart(labels: Sequence[str], counts: Sequence[int], links: Sequence[str], title: str, chart_id: str) -> str:
    """Vertical bars of the matches covering each bin, each bar a link (``links[k]``); a bin no
    match covers (a gap) is marked by a red stripe on the axis."""
    left, width, plot_height, top = 40, 620, 150, 34
    most = max(counts, default=0) or 1
    step = width / max(len(counts), 1)
    parts = [_title(title)]
    for k, (label, count, link) in enumerate(zip(labels, counts, links)):
        h = plot_height * count / most
        x = left + k * step
        tip = f"<title>{html.escape(label)}: {count} matches{' (gap)' if not count else ''}</title>"
        bar = (
            f'<rect x="{x:.1f}" y="{top + plot_height - h:.1f}" width="{max(step - 2, 1):.1f}" height="{h:.1f}" '
            f'fill="{BAR_COLOUR}">{tip}</rect>'
            if count
            else f'<rect class="gap" x="{x:.1f}" y="{top + plot_height - 4}" width="{max(step - 2, 1):.1f}" '
            f'height="4" fill="{GAP_COLOUR}">{tip}</rect>'
        )
        parts.append(f'<a href="{html.escape(link)}">{bar}</a>' if count else bar)
        if count:
            parts.append(
                f'<text x="{x + step / 2:.1f}" y="{top + plot_height - h - 3:.1f}" text-anchor="middle">{count}</text>'
            )
    for k in range(0, len(labels), max(1, len(labels) // 6)):
        parts.append(
            f'<text x="{left + (k + 0.5) * step:.1f}" y="{top + plot_height + 16}" text-anchor="middle">'
            f"{html.escape(_short(labels[k], 18))}</text>"
        )
    return _svg(chart_id, left + width + 20, top + plot_height + 26, parts)


def heat_map(cells: np.ndarray, rows: Sequence[str], columns: Sequence[str], title: str, chart_id: str) -> str:
    """A grid of counts (``cells[i, j]``; rows and columns named by bins), darker for more; empty
    cells are outlined only."""
    size = max(6.0, min(24.0, 480 / max(cells.shape[0], cells.shape[1], 1)))
    left, top = 120, 34
    most = int(cells.max()) if cells.size else 0
    parts = [_title(title)]
    for (i, j), count in np.ndenumerate(cells):
        shade = 0.15 + 0.85 * count / most if count else 0
        fill = f'fill="{BAR_COLOUR}" fill-opacity="{shade:.2f}"' if count else 'fill="none" stroke="#ddd"'
        parts.append(
            f'<rect x="{left + j * size:.1f}" y="{top + i * size:.1f}" width="{size - 1:.1f}" height="{size - 1:.1f}" '
            f"{fill}><title>{html.escape(rows[i])} × {html.escape(columns[j])}: {count}</title></rect>"
        )
    for i in range(0, len(rows), max(1, len(rows) // 8)):
        parts.append(
            f'<text x="{left - 4}" y="{top + (i + 0.7) * size:.1f}" text-anchor="end">'
            f"{html.escape(_short(rows[i], 18))}</text>"
        )
    bottom = top + len(rows) * size
    for j in range(0, len(columns), max(1, len(columns) // 6)):
        parts.append(
            f'<text x="{left + (j + 0.5) * size:.1f}" y="{bottom + 14:.1f}" text-anchor="middle">'
            f"{html.escape(_short(columns[j], 14))}</text>"
        )
    return _svg(chart_id, left + len(columns) * size + 40, bottom + 24, parts)
