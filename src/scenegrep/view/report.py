"""The report over a whole results table: counts per trace, every match linked to its view, charts.

``write_report`` writes the page and, in a folder beside it (``<stem>_views/``), the HTML view
of every trace with a match (:mod:`.page`); each match of the page links to its trace's view at
that match (``#match=N``). The page is static and self-contained like the views.
"""

from __future__ import annotations

import html
import json
import re
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ..writers.atomic import atomic_path
from .charts import bar_chart, histogram
from .page import asset, html_page, view_page
from .sources import ResultsSource
from ..wording import counted

MOST_BARS = 40
"""The matches-per-trace chart shows the traces with the most matches, at most this many."""


def view_file(trace_id: str) -> str:
    """A file name for a trace's view (the id with anything but letters, digits, '-', '_' and '.' replaced)."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", trace_id) + ".html"


def write_report(source: ResultsSource, path: str | Path, progress: Callable[[Iterable], Iterable] = iter) -> int:
    """Write the report of ``source`` to ``path`` and the views of its matched traces beside it;
    returns the number of views written. ``progress`` wraps the loop over the views (a bar)."""
    path = Path(path)
    written, link = write_views(source, path, progress)
    page = report_page(source, link)
    with atomic_path(path) as tmp:
        tmp.write_text(page, encoding="utf-8")
    return written


def write_views(
    source: ResultsSource, page: Path, progress: Callable[[Iterable], Iterable] = iter
) -> tuple[int, Callable[[str, int], str]]:
    """Write the view of every matched trace of ``source`` into ``<stem>_views/`` beside the page
    ``page`` (each linking back to it); returns how many, and ``link(trace_id, match_number)``:
    the address, relative to the page, of a match's view."""
    folder = page.with_name(f"{page.stem}_views")
    written = 0
    for trace_id in progress(source.matched_trace_ids()):
        view = source.view(trace_id)
        with atomic_path(folder / view_file(view.trace_id)) as tmp:
            tmp.write_text(view_page(view, back_link=f"../{page.name}"), encoding="utf-8")
        written += 1
    return written, lambda trace_id, number: f"{folder.name}/{view_file(trace_id)}#match={number}"


def report_page(source: ResultsSource, link: Callable[[str, int], str]) -> str:
    """The report's HTML; ``link(trace_id, match_number)`` is the address of a match's view."""
    rows = source.results.table.to_pylist()
    matches = [r for r in rows if r["status"] == "match"]
    kinds = source.object_kinds({r["trace_id"] for r in rows})
    query = source.query
    body = asset("report.html").format(
        query=html.escape(f"{query.kind}: {query.text}" if query else "(query unknown)"),
        run=html.escape(f"run {source.results.run_id} ({source.results.status})" if source.results.run_id else ""),
        summary=_summary(source, matches),
        charts=_charts(rows, matches, kinds),
        matches=_matches_table(matches, link),
        traces=_traces_table(rows, link),
    )
    return html_page(f"scenegrep report · {source.results.run_id or 'results'}", asset("report.css"), body)


def _summary(source: ResultsSource, matches: list[dict[str, Any]]) -> str:
    counts = source.results.counts()
    cards = [
        ("traces", counts["traces"]),
        ("matched", counts["matched"]),
        ("matches", len(matches)),
        ("no match", counts["traces"] - counts["matched"] - counts["pruned"] - counts["failed"]),
        ("pruned", counts["pruned"]),
        ("failed", counts["failed"]),
    ]
    return "".join(
        f'<div class="card" data-count="{html.escape(name)}"><b>{value}</b><span>{html.escape(name)}</span></div>'
        for name, value in cards
    )


def _charts(rows: list[dict[str, Any]], matches: list[dict[str, Any]], kinds: dict[tuple[str, str], str]) -> str:
    per_trace = Counter(r["name"] for r in matches)
    top = per_trace.most_common(MOST_BARS)
    charts = [
        bar_chart(
            [name for name, _ in top],
            [[n for _, n in top]],
            ["matches"],
            f"Matches per trace ({counted(len(per_trace), 'trace')} with a match"
            + (f"; the {MOST_BARS} with the most)" if len(per_trace) > MOST_BARS else ")"),
            "chart-matches",
        ),
        histogram(
            [r["end_time"] - r["start_time"] for r in matches],
            "Window lengths of the matches",
            "seconds",
            "chart-windows",
        ),
    ]
    bound = Counter(kinds.get((r["trace_id"], o), "?") for r in matches for o in _correspondence(r).values())
    if bound:
        labels = sorted(bound, key=lambda k: -bound[k])
        charts.append(
            bar_chart(
                labels, [[bound[k] for k in labels]], ["objects"], "Kinds of the corresponded objects", "chart-bound"
            )
        )
    matched = {r["trace_id"] for r in matches}
    everywhere = Counter(kind for (_, _), kind in kinds.items())
    in_matched = Counter(kind for (trace, _), kind in kinds.items() if trace in matched)
    labels = sorted(everywhere, key=lambda k: -everywhere[k])
    charts.append(
        bar_chart(
            labels,
            [[everywhere[k] for k in labels], [in_matched[k] for k in labels]],
            ["in all traces", "in matched traces"],
            "Objects per kind",
            "chart-kinds",
        )
    )
    return "".join(f"<figure>{chart}</figure>" for chart in charts)


def _correspondence(row: dict[str, Any]) -> dict[str, str]:
    return json.loads(row["correspondence"]) if row["correspondence"] else {}


def _matches_table(matches: list[dict[str, Any]], link: Callable[[str, int], str]) -> str:
    lines = []
    for k, r in enumerate(matches):
        pairs = ", ".join(f"{name} = {oid}" for name, oid in _correspondence(r).items())
        lines.append(
            f'<tr><td>{k}</td><td><a class="match-link" href="{html.escape(link(r["trace_id"], r["match"]))}" '
            f'data-trace="{html.escape(r["trace_id"])}" data-match="{r["match"]}" data-start="{r["start_frame"]}" '
            f'data-end="{r["end_frame"]}" data-correspondence="{html.escape(r["correspondence"] or "{}")}">'
            f"{html.escape(r['name'])} · {r['match']}</a></td><td>{r['start_frame']}–{r['end_frame']}</td>"
            f"<td>{r['start_time']:.1f}–{r['end_time']:.1f}</td><td>{html.escape(pairs)}</td></tr>"
        )
    return "".join(lines) or '<tr><td colspan="5">no match</td></tr>'


def _traces_table(rows: list[dict[str, Any]], link: Callable[[str, int], str]) -> str:
    traces: dict[str, dict[str, Any]] = {}
    for r in rows:
        entry = traces.setdefault(r["trace_id"], {"name": r["name"], "status": r["status"], "matches": 0, "note": ""})
        entry["matches"] += r["status"] == "match"
        entry["note"] = entry["note"] or (r["error"] or r["explanation"] or "" if r["status"] != "match" else "")
    lines = []
    for trace_id, t in sorted(traces.items(), key=lambda item: (-item[1]["matches"], item[1]["name"])):
        name = html.escape(t["name"])
        cell = f'<a href="{html.escape(link(trace_id, 0))}">{name}</a>' if t["matches"] else name
        note = html.escape(t["note"].splitlines()[0] if t["note"] else "")
        lines.append(
            f'<tr class="{t["status"].replace(" ", "-")}"><td>{cell}</td><td>{t["status"]}</td>'
            f"<td>{t['matches']}</td><td>{note}</td></tr>"
        )
    return "".join(lines)
