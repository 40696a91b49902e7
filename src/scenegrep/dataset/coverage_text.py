"""The text summary of a coverage (:mod:`.coverage`): per variable its domain, the matches per
bin, the gaps and the ambiguous matches; the joint coverage of pairs; bins covered per source."""

from __future__ import annotations

from .coverage import AMBIGUOUS, NO_VALUE, Coverage
from ..wording import counted

MOST_SOURCES = 20
"""Sources listed in the per-source part (the table has them all)."""


def summary_text(coverage: Coverage, program: str) -> str:
    """The summary, several lines (no trailing newline)."""
    rows = coverage.rows
    lines = [
        f"coverage of {program}: {counted(len(rows), 'match')} in "
        f"{counted(len({r['trace_id'] for r in rows}), 'trace')} from {counted(len(coverage.sources), 'source')}; "
        f"{coverage.ambiguous()} ambiguous (an interval over several bins), "
        f"{coverage.several()} with several correspondences"
    ]
    if coverage.unknown:
        lines.append(
            f"unknown: {coverage.unknown}; bins no match covers are not gaps there (uncovered, not known empty)"
        )
    for a, axis in enumerate(coverage.axes):
        counts = coverage.counts(a).tolist()
        column = coverage.assigned[:, a]
        covered = sum(1 for n in counts if n)
        lines.append(f"{axis.name} (line {axis.declared.line}): {axis.domain_text()}")
        lines.append("  " + "  ".join(f"{axis.label(k)} {n}" for k, n in enumerate(counts)))
        lines.append(
            f"  covered {covered} of {counted(axis.bins, 'bin')} by {counted(sum(counts), 'match')}; "
            f"ambiguous {int((column == AMBIGUOUS).sum())}; without a value {int((column == NO_VALUE).sum())}"
        )
        gaps = [axis.label(k) for k, n in enumerate(counts) if not n]
        named = "uncovered in the data decided" if coverage.unknown else "gaps"
        lines.append(f"  {named}: {', '.join(gaps) if gaps else 'none'}")
    if coverage.pairs():
        lines.append("joint coverage (cells of two bins that one match covers):")
        for a, b in coverage.pairs():
            cells = coverage.joint(a, b)
            lines.append(
                f"  {coverage.axes[a].name} × {coverage.axes[b].name}: {int((cells > 0).sum())} of {cells.size} cells"
            )
    if len(coverage.sources) > 1:
        lines.append("bins covered per source:")
        for source in coverage.sources[:MOST_SOURCES]:
            per = ", ".join(
                f"{axis.name} {int((coverage.counts(a, source) > 0).sum())}/{axis.bins}"
                for a, axis in enumerate(coverage.axes)
            )
            lines.append(f"  {source}: {per}")
        if len(coverage.sources) > MOST_SOURCES:
            lines.append(f"  ... and {len(coverage.sources) - MOST_SOURCES} more sources (see --output)")
    return "\n".join(lines)
