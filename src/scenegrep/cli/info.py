"""``scenegrep info PATH...``: what an input holds (format, frames, duration, objects per class, map).

A folder of trace files is summarised file by file, as the query commands find them; over a
folder or several paths an unreadable input is one ``scenegrep: failed:`` line on stderr and the
others are summarised (exit code 3). One bad file given alone is a user error (exit code 2).
"""

from __future__ import annotations

import argparse
from typing import Any

from ..wording import counted
from .inputs import each_input
from .options import add_bag_arguments


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "info",
        help="summarise traces and maps of any supported input",
        description="Summarise any supported input: format detected, frames, "
        "duration, objects per class, map elements.",
    )
    parser.add_argument("paths", nargs="+", metavar="PATH", help="file or recording directory (- for stdin)")
    parser.add_argument("--json", action="store_true", help="print JSON Lines: one object per input")
    parser.add_argument("--no-map", action="store_true", help="do not load the traces' maps")
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def _classes(counts: dict[str, int]) -> str:
    return ", ".join(f"{name} {n}" for name, n in counts.items()) or "none"


def _trace_lines(t: dict[str, Any]) -> list[str]:
    duration = "unknown duration" if t["duration_s"] is None else f"{t['duration_s']:.2f} s"
    rate = f" at {t['rate_hz']:.1f} Hz" if t["rate_hz"] else ""
    ego = f", ego {t['ego']}" if t["ego"] else ""
    sizes = f"{counted(t['frames'], 'frame')}, {duration}{rate}, {counted(t['objects'], 'object')}"
    lines = [f"  trace {t['name']}: {sizes}{ego}"]
    if t["objects"]:
        lines.append(f"    objects per class: {_classes(t['objects_per_class'])}")
        lines.append(f"    states: {t['states']} ({t['states_with_lane']} with a lane)")
    if "behaviour_labels" in t:
        lines.append(f"    behaviour labels: {_classes(t['behaviour_labels'])}")
    if "image_samples_per_channel" in t:
        lines.append(f"    image samples per channel: {_classes(t['image_samples_per_channel'])}")
        lines.append(f"    image boxes per class: {_classes(t['image_boxes_per_class'])}")
    return lines


def _topic_line(t: dict[str, Any]) -> str:
    rate = "" if t["rate_hz"] is None else f", {t['rate_hz']:.1f} Hz"
    skipped = "" if t["decoded"] else " (not read: unsupported type)"
    return f"  topic {t['topic']}: {t['type']} [{t['encoding']}], {counted(t['messages'], 'message')}{rate}{skipped}"


def _map_lines(m: dict[str, Any]) -> list[str]:
    stop_lines = f", {counted(m['stop_lines'], 'stop line')}" if m.get("stop_lines") else ""
    unknown = f"; unknown (not published): {', '.join(m['unknown_layers'])}" if m["unknown_layers"] else ""
    return [
        f"  map {m['name']}: {counted(m['lanes'], 'lane')} ({m['intersection_lanes']} in intersections), "
        f"{counted(m['roads'], 'road')}, {counted(m['intersections'], 'intersection')}, "
        f"{counted(m['crosswalks'], 'crosswalk')}, {counted(m['sidewalks'], 'sidewalk')}, "
        f"{counted(m['curbs'], 'curb')}{stop_lines}{unknown}; "
        f"extent {m['extent_m'][0]} x {m['extent_m'][1]} m"
    ]


def run(args: argparse.Namespace) -> int:
    """Print each input's summary; over a folder or several paths an unreadable input is a
    failed line on stderr and the others are summarised (exit code 3), see :mod:`.inputs`."""
    return each_input(args.paths, lambda path: _print_summary(path, args))


def _print_summary(path: str, args: argparse.Namespace) -> None:
    """Print the summary of one input: one JSON Lines record with ``--json``, else text lines."""
    from ..summary import describe

    summary = describe(path, with_map=not args.no_map)
    if args.json:
        from ..json_lines import write

        write(summary)
        return
    print(f"{path}: {summary['description']} [{summary['format']}]")
    for topic in summary.get("topics", []):
        print(_topic_line(topic))
    for trace in summary["traces"]:
        print("\n".join(_trace_lines(trace)))
    for road_map in summary.get("maps", []):
        print("\n".join(_map_lines(road_map)))
