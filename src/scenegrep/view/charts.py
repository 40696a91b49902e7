"""Small SVG charts for the report page: drawn here, so the page needs no script library or network."""

from __future__ import annotations

import html
from collections.abc import Sequence

import numpy as np

BAR_COLOUR = "#4c78a8"


def bar_chart(
    labels: Sequence[str], series: Sequence[Sequence[float]], names: Sequence[str], title: str, chart_id: str
) -> str:
    """Horizontal bars, one group per label and one bar per series (each with its legend name)."""
    colours = ("#4c78a8", "#f58518", "#54a24b", "#e45756")
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
