"""The coverage page: a program's parameter space as the matches of a run cover it.

``write_coverage_page`` writes one self-contained HTML page in the style of the report
(:mod:`.report`): summary cards, per axis a chart of the matches covering each bin (gaps marked
red and listed) whose bars link to the bin's list of matches, the joint coverage of pairs of
axes as heat maps, bins covered per source, and per covered bin its matches, each linking to
its trace's view (written to ``<stem>_views/`` beside the page, as the report's).
"""

from __future__ import annotations

import html
from collections.abc import Callable, Iterable
from pathlib import Path

from ..dataset.coverage import AMBIGUOUS, NO_VALUE, Coverage
from ..writers.atomic import atomic_path
from .charts import bin_chart, heat_map
from .page import asset, html_page
from .report import write_views
from .sources import ResultsSource

MOST_LISTED = 200
"""Matches listed per bin (the count says how many there are)."""

MOST_SOURCES = 500
"""Sources in the per-source table (the coverage table has them all)."""


def write_coverage_page(
    source: ResultsSource, coverage: Coverage, path: str | Path, progress: Callable[[Iterable], Iterable] = iter
) -> int:
    """Write the page to ``path`` (.html) and the views of the matched traces beside it; returns
    the number of views written."""
    path = Path(path)
    written, link = write_views(source, path, progress)
    with atomic_path(path) as tmp:
        tmp.write_text(coverage_page(source, coverage, link), encoding="utf-8")
    return written


def coverage_page(source: ResultsSource, coverage: Coverage, link: Callable[[str, int], str]) -> str:
    """The page's HTML; ``link(trace_id, match_number)`` is the address of a match's view."""
    query = source.query
    parts = [
        "<h1>scenegrep coverage</h1>",
        f'<pre id="query">{html.escape(f"{query.kind}: {query.text}" if query else "(query unknown)")}</pre>',
        f'<section id="summary">{_cards(coverage)}</section>',
        *(
            [
                f'<p id="unknown" class="gaps">unknown: {html.escape(coverage.unknown)}; bins no match covers are '
                "uncovered in the data decided, not known gaps</p>"
            ]
            if coverage.unknown
            else []
        ),
        "<h2>Variables</h2>",
        '<section id="charts">',
        *(_axis_figure(coverage, a) for a in range(len(coverage.axes))),
        "</section>",
    ]
    if coverage.pairs():
        parts += ["<h2>Joint coverage</h2>", '<section id="pairs">', *_pairs(coverage), "</section>"]
    parts += ["<h2>Per source</h2>", _sources_table(coverage), "<h2>Matches per bin</h2>", _bin_lists(coverage, link)]
    return html_page("scenegrep coverage", asset("report.css"), "\n".join(parts))


def _cards(coverage: Coverage) -> str:
    cards = [
        ("matches", len(coverage.rows)),
        ("traces", len({r["trace_id"] for r in coverage.rows})),
        ("sources", len(coverage.sources)),
        ("ambiguous", coverage.ambiguous()),
        ("several correspondences", coverage.several()),
        ("variables", len(coverage.axes)),
    ]
    return "".join(
        f'<div class="card" data-count="{html.escape(name)}"><b>{value}</b><span>{html.escape(name)}</span></div>'
        for name, value in cards
    )


def _axis_figure(coverage: Coverage, a: int) -> str:
    axis = coverage.axes[a]
    counts = coverage.counts(a).tolist()
    labels = [axis.label(k) for k in range(axis.bins)]
    chart = bin_chart(labels, counts, [f"#bin-{a}-{k}" for k in range(axis.bins)], axis.name, f"chart-axis-{a}")
    column = coverage.assigned[:, a]
    gaps = [labels[k] for k, n in enumerate(counts) if not n]
    caption = (
        f"{html.escape(axis.domain_text())}; {sum(1 for n in counts if n)} of {axis.bins} bins covered; "
        f"{int((column == AMBIGUOUS).sum())} ambiguous, {int((column == NO_VALUE).sum())} without a value"
        f'<br><span class="gaps">{"uncovered in the data decided" if coverage.unknown else "gaps"}: '
        f"{html.escape(', '.join(gaps) if gaps else 'none')}</span>"
    )
    return f'<figure data-axis="{html.escape(axis.name)}">{chart}<figcaption>{caption}</figcaption></figure>'


def _pairs(coverage: Coverage) -> list[str]:
    figures = []
    for a, b in coverage.pairs():
        cells = coverage.joint(a, b)
        first, second = coverage.axes[a], coverage.axes[b]
        title = f"{first.name} × {second.name}: {int((cells > 0).sum())} of {cells.size} cells"
        rows = [first.label(k) for k in range(first.bins)]
        columns = [second.label(k) for k in range(second.bins)]
        figures.append(f"<figure>{heat_map(cells, rows, columns, title, f'chart-pair-{a}-{b}')}</figure>")
    return figures


def _sources_table(coverage: Coverage) -> str:
    head = "".join(f"<th>{html.escape(axis.name)}</th>" for axis in coverage.axes)
    lines = []
    for source in coverage.sources[:MOST_SOURCES]:
        cells = "".join(
            f"<td>{int((coverage.counts(a, source) > 0).sum())} / {axis.bins}</td>"
            for a, axis in enumerate(coverage.axes)
        )
        lines.append(f"<tr><td>{html.escape(source)}</td>{cells}</tr>")
    body = "".join(lines) or f'<tr><td colspan="{len(coverage.axes) + 1}">no match</td></tr>'
    return (
        f'<table id="sources"><thead><tr><th>source (bins covered)</th>{head}</tr></thead><tbody>{body}</tbody></table>'
    )


def _bin_lists(coverage: Coverage, link: Callable[[str, int], str]) -> str:
    sections = []
    for a, axis in enumerate(coverage.axes):
        for k in range(axis.bins):
            found = coverage.matches_in(a, k)
            if not found:
                continue
            items = []
            for m in found[:MOST_LISTED]:
                r = coverage.rows[m]
                value = axis.label(k) if axis.edges is None else f"[{coverage.lo[m, a]:.6g}, {coverage.hi[m, a]:.6g}]"
                items.append(
                    f'<li><a class="match-link" href="{html.escape(link(r["trace_id"], r["match"]))}">'
                    f"{html.escape(r['name'])} · {r['match']}</a> frames {r['start_frame']}–{r['end_frame']}: "
                    f"{html.escape(value)}</li>"
                )
            more = f"<li>… and {len(found) - MOST_LISTED} more</li>" if len(found) > MOST_LISTED else ""
            sections.append(
                f'<section id="bin-{a}-{k}" class="bin"><h3>{html.escape(axis.name)} {html.escape(axis.label(k))}: '
                f"{len(found)} matches</h3><ul>{''.join(items)}{more}</ul></section>"
            )
    return "".join(sections) or "<p>no bin is covered</p>"
