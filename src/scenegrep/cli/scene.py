"""``scenegrep scene PROGRAM.scenic DATA...``: the labeled frames that are scenes of a Scenic program.

Output is one line per matching frame, ``SOURCE:FRAME`` followed by the object
correspondence and the values of the program's random variables; ``--json``
prints one JSON object per line instead, ``--parquet FILE`` also writes the
matches as a table. ``--explain`` adds a line for every frame that does not
match, naming the first features no correspondence satisfied. When no frame matches, the
nearest misses (:mod:`.misses`) follow on stderr. Exit codes: 0 some frame matches, 1 none,
2 error.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from .dataset_run import add_dataset_arguments, reject_dataset_only, run_dataset

NO_MATCH = 1


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "scene",
        help="find the labeled frames that are scenes of a Scenic program",
        description="Find the labeled frames that are instances of the static scene a Scenic program describes "
        "(seed 003): some injective correspondence of the program's objects to labeled objects, and some values "
        "of its random variables, reproduce the labeled positions, headings and explicit sizes within tolerance, "
        "and every require holds. DATA is any supported input (scenegrep traces, AV2, nuScenes, Waymo, "
        "CommonRoad, Scenic-generated scenes).",
    )
    parser.add_argument("program", metavar="PROGRAM", help="a .scenic file")
    parser.add_argument("data", nargs="*", metavar="DATA", help="labeled traces (files or recording directories)")
    add_tolerance_arguments(parser)
    parser.add_argument("--exact", action="store_true", help="every labeled object in view must be matched")
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="ignore objects and map farther than M from the ego"
    )
    parser.add_argument("--explain", action="store_true", help="also say why each other frame does not match")
    parser.add_argument("--no-values", action="store_true", help="do not compute the random values of matches")
    parser.add_argument("--json", action="store_true", help="print one JSON object per frame")
    parser.add_argument("--parquet", metavar="FILE", help="also write the matches as a Parquet table")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    add_dataset_arguments(parser)
    parser.set_defaults(run=run)


def add_tolerance_arguments(parser: argparse.ArgumentParser) -> None:
    """``--map`` and the scene tolerances, shared by the Scenic query commands."""
    from ..scene.profiles import PROFILES

    parser.add_argument("--map", metavar="MAP", help="road map for traces without one (e.g. an .xodr file)")
    parser.add_argument(
        "--tolerance-profile",
        metavar="NAME",
        help=f"tolerances measured on a dataset's labels ({', '.join(PROFILES)}; default exact); "
        "--tolerance-position, --tolerance-heading and --tolerance-speed override its values",
    )
    parser.add_argument(
        "--tolerance-position", type=float, metavar="M", help="position and size tolerance (m; default 1e-6)"
    )
    parser.add_argument("--tolerance-heading", type=float, metavar="RAD", help="heading tolerance (rad; default 1e-6)")
    parser.add_argument(
        "--tolerance-speed", type=float, metavar="M/S", help="speed and velocity tolerance (m/s; default 1e-6)"
    )


def tolerance_of(args: argparse.Namespace) -> Any:
    """The :class:`~scenegrep.scene.Tolerance` the options give: the profile's, each given tolerance
    instead of its value (unknown profiles and negative values are user errors)."""
    from ..scene.profiles import tolerance_of

    return tolerance_of(
        args.tolerance_profile,
        position=args.tolerance_position,
        heading=args.tolerance_heading,
        speed=args.tolerance_speed,
    )


def tolerance_options(args: argparse.Namespace) -> dict[str, Any]:
    """The tolerance options as dataset query options (checked)."""
    tolerance_of(args)
    return {
        "tolerance_profile": args.tolerance_profile,
        "tolerance_position": args.tolerance_position,
        "tolerance_heading": args.tolerance_heading,
        "tolerance_speed": args.tolerance_speed,
    }


def _value_text(values: dict[str, Any]) -> str:
    def show(v: Any) -> str:
        if isinstance(v, float):
            return f"{v:.6g}"
        if isinstance(v, list):
            return "(" + ", ".join("?" if c is None else f"{c:.6g}" for c in v) + ")"
        return "?" if v is None else str(v)

    return "  ".join(f"{name}={show(v)}" for name, v in values.items())


def _place(trace: Any, source: str, frame: int) -> dict[str, Any]:
    return {
        "source": source,
        "trace": trace.name,
        "frame": int(trace.frame_index[frame]),
        "time": float(trace.frame_time[frame]),
    }


def _records(result: Any, source: str, args: argparse.Namespace) -> list[dict[str, Any]]:
    trace = result.trace
    soft = result.soft
    records = []
    for k, frame in enumerate(result.frames().tolist()):
        record: dict[str, Any] = {**_place(trace, source, frame), "match": True}
        record["correspondence"] = result.correspondence(frame)
        if not args.no_values:
            record["values"] = result.values(frame)
        if soft:
            record["soft"] = {name: bool(holds[k]) for name, holds in soft.items()}
        records.append(record)
    if args.explain:
        for frame in (~result.matched).nonzero()[0].tolist():
            records.append({**_place(trace, source, frame), "match": False, "failure": result.failure(frame)})
        records.sort(key=lambda r: r["time"])
    return records


def _line(record: dict[str, Any], args: argparse.Namespace) -> str:
    if args.json:
        return json.dumps(record, allow_nan=True)
    place = f"{record['source']}:{record['frame']}"
    if not record["match"]:
        return f"{place}  no match: {record['failure']}"
    pairs = "  ".join(f"{k}={v}" for k, v in record["correspondence"].items())
    text = f"{place}  {pairs}"
    if record.get("values"):
        text += "  |  " + _value_text(record["values"])
    if "soft" in record:
        text += "  |  " + "  ".join(f"[{'holds' if ok else 'fails'}] {name}" for name, ok in record["soft"].items())
    return text


def _run_dataset(args: argparse.Namespace) -> int:
    from ..scenic.parser import read_program

    options = {"visible_distance": args.visible_distance, "exact": args.exact, "explain": args.explain}
    return run_dataset(args, "scene", read_program(args.program), args.program, options | tolerance_options(args))


def run(args: argparse.Namespace) -> int:
    from .. import readers
    from ..errors import UserError
    from ..scene import SceneOptions, load_scene
    from .misses import MissCollector

    if args.dataset:
        return _run_dataset(args)
    reject_dataset_only(args)
    if not args.data:
        raise UserError("give DATA (trace files or directories) or --dataset")

    query = load_scene(args.program, args.visible_distance)
    options = SceneOptions(tolerance_of(args), args.exact, args.visible_distance)
    road_map = readers.read_map(args.map) if args.map else None
    rows: list[dict[str, Any]] = []
    found = False
    frames = matched = 0
    notes: dict[str, int] = {}
    misses = MissCollector()
    for path in args.data:
        many = readers.FORMATS[readers.detect_format(path)].many
        for trace in readers.read_traces(path):
            result = query.match(trace, road_map, options)
            source = f"{path}#{trace.name}" if many else path
            records = _records(result, source, args)
            frames += trace.n_frames
            matched += int(result.matched.sum())
            found |= bool(result.matched.any())
            if not found:
                misses.offer(source, lambda result=result: (result, None))
            for key, count in result.matches.notes.items():
                notes[key] = notes.get(key, 0) + count
            if not args.quiet:
                for record in records:
                    sys.stdout.write(_line(record, args) + "\n")
            rows.extend(r for r in records if r["match"])
    if args.parquet:
        _write_parquet(rows, args.parquet)
    if not args.quiet:
        _notes(notes, matched, frames)
        if not found:
            misses.report(args.json)
    return 0 if found else NO_MATCH


def _notes(notes: dict[str, int], matched: int, frames: int) -> None:
    print(f"scenegrep: {matched} of {frames} frames match", file=sys.stderr)
    loose = {k: v for k, v in notes.items() if k.endswith(("delta-sat", "undecided"))}
    for key, count in sorted(loose.items()):
        solver, status = key.rsplit(":", 1)
        meaning = (
            "satisfiable after relaxing by the solver's δ (may be a false positive within δ)"
            if status == "delta-sat"
            else "not decided within the solver's budget (kept: may be a false positive)"
        )
        print(f"scenegrep: note: {count} candidate correspondences were {meaning}", file=sys.stderr)


def _write_parquet(rows: list[dict[str, Any]], path: str) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from ..writers.atomic import atomic_path

    table = pa.table(
        {
            "source": [r["source"] for r in rows],
            "trace": [r["trace"] for r in rows],
            "frame": pa.array([r["frame"] for r in rows], pa.int64()),
            "time": pa.array([r["time"] for r in rows], pa.float64()),
            "correspondence": [json.dumps(r["correspondence"]) for r in rows],
            "values": [json.dumps(r.get("values", {}), allow_nan=True) for r in rows],
        }
    )
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
