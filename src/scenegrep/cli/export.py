"""``scenegrep export RESULTS -o OUT [--format mcap|refav|openscenario|scenic]``: a results table for
other tools.

``-o/--output OUT`` names what is written, as in every command; the kind is ``--format``'s, else
OUT's suffix says it (``.mcap``: MCAP events; ``.pkl``, ``.json``: a RefAV submission); a folder
needs ``--format`` (``openscenario`` or ``scenic``). ``--mcap OUT``, ``--refav OUT``,
``--openscenario DIR`` and ``--scenic DIR`` are the same as ``-o`` with that format.

RESULTS is a results table (Parquet, JSON lines or CSV) or a run directory. ``--mcap`` writes
its matches as Foxglove events; ``--refav`` writes a RefAV scenario-mining submission
(:mod:`scenegrep.dataset.refav_export`): RefAV's own pickle when OUT ends in ``.pkl``, the same
data as JSON (which ``scenegrep evaluate`` reads) when it ends in ``.json``; ``--openscenario``
writes every match as an OpenSCENARIO 1.3 file in DIR (:mod:`scenegrep.dataset.openscenario_export`);
``--scenic`` every match as a Scenic program that re-runs it (:mod:`scenegrep.dataset.scenic_export`).
With either, ``--context R`` adds the labeled objects within R m. Exit codes: 0 written, 2 user error.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..wording import counted, verb


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "export",
        help="write a results table for other tools (Foxglove MCAP events, RefAV submission, OpenSCENARIO, Scenic)",
        description="Write the matches of a results table as Foxglove events (schema foxglove.Event, topic "
        "/scenegrep/matches) in an MCAP file: each event spans the window's first to last frame at the "
        "recording's absolute time, with the trace and the correspondence as metadata. Or, for results over "
        "Argoverse 2 sensor logs, write a RefAV scenario-mining submission: per (log id, prompt), at every "
        "2 Hz evaluation timestamp, the boxes of the tracks the referred program object corresponds to.",
    )
    parser.add_argument("results", metavar="RESULTS", help="a results table (.parquet/.json/.csv) or a run directory")
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        help="the file or folder to write, of --format's kind (default: by OUT's suffix, .mcap or .pkl/.json)",
    )
    target.add_argument("--mcap", metavar="OUT", help="the MCAP file to write")
    target.add_argument("--refav", metavar="OUT", help="the RefAV submission to write: OUT.pkl (RefAV's) or OUT.json")
    target.add_argument(
        "--openscenario", metavar="DIR", help="the folder to write each match to as OpenSCENARIO (.xosc)"
    )
    target.add_argument("--scenic", metavar="DIR", help="the folder to write each match to as a Scenic program")
    parser.add_argument(
        "--format",
        choices=FORMATS,
        help="with -o: what to write (mcap: Foxglove events; refav: a RefAV submission; openscenario, scenic: a "
        "folder of one file per match)",
    )
    parser.add_argument(
        "--context",
        metavar="R",
        type=float,
        help="--openscenario, --scenic: also every labeled object within R m of a corresponded one (default: none)",
    )
    parser.add_argument("--prompt", metavar="TEXT", help="--refav: the RefAV prompt the query answers")
    parser.add_argument(
        "--referred",
        metavar="NAME",
        help="--refav: the program object the prompt refers to (default: the one besides ego)",
    )
    parser.add_argument(
        "--dataset",
        metavar="DATASET",
        help="--refav, --openscenario, --scenic: the dataset of the results (default: where they lie)",
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(run=run)


FORMATS = ("mcap", "refav", "openscenario", "scenic")
"""What ``export`` writes; each is also an option naming its output (``--mcap OUT``)."""

SUFFIXES = {".mcap": "mcap", ".pkl": "refav", ".json": "refav"}
"""The kind an output file's suffix says, when ``--format`` does not."""


def output_kind(output: str, kind: str | None) -> str:
    """What ``-o OUT`` writes: ``kind`` (``--format``), else the kind ``output``'s suffix says
    (any case); UserError when neither says."""
    if kind is not None:
        return kind
    found = SUFFIXES.get(Path(output).suffix.lower())
    if found is None:
        raise UserError(
            f"-o {output}: say what to write with --format {'|'.join(FORMATS)} (a .mcap file is MCAP events, a .pkl "
            "or .json file a RefAV submission)"
        )
    return found


def run(args: argparse.Namespace) -> int:
    if args.format is not None and args.output is None:
        raise UserError(f"--format goes with -o/--output (or write --{args.format} OUT)")
    if args.output is not None:
        setattr(args, output_kind(args.output, args.format), args.output)
    for kind in ("mcap", "refav"):
        if getattr(args, kind) is not None and not getattr(args, kind).strip():
            raise UserError(f"{_option(args, '--' + kind)}: give the file to write to")
    if args.context is not None and args.openscenario is None and args.scenic is None:
        raise UserError("--context goes with --openscenario or --scenic")
    if args.scenic is not None:
        return _scenic(args)
    if args.refav is not None:
        return _refav(args)
    if args.openscenario is not None:
        return _openscenario(args)
    if args.prompt is not None or args.referred is not None or args.dataset is not None:
        raise UserError("--prompt, --referred and --dataset go with --refav")
    from ..dataset.export import write_mcap_events
    from ..dataset.results import Results

    count = write_mcap_events(Results.read(args.results), args.mcap)
    if not args.quiet:
        print(f"scenegrep: {counted(count, 'match')} written as Foxglove events to {args.mcap}", file=sys.stderr)
    return 0


def _refav(args: argparse.Namespace) -> int:
    from ..dataset.refav_export import check_request, refav_sequences
    from ..dataset.refav_format import sequence_counts, write_sequences
    from ..dataset.results_traces import ResultsTraces

    if args.output is not None and not args.prompt:
        raise UserError(f"-o {args.output}: a RefAV submission needs --prompt TEXT: RefAV keys it by (log id, prompt)")
    check_request(args.refav, args.prompt)
    source = ResultsTraces.open(args.results, args.dataset)
    sequences = refav_sequences(source.results, source.trace, args.prompt, args.referred)
    write_sequences(sequences, args.refav)
    if not args.quiet:
        logs, positive, frames = sequence_counts(sequences)
        print(
            f"scenegrep: {counted(logs, 'log')} ({positive} with a referred track), "
            f"{counted(frames, 'evaluation timestamp')} "
            f"written to {args.refav}",
            file=sys.stderr,
        )
    return 0


def _option(args: argparse.Namespace, option: str) -> str:
    """How the user named the output: ``-o``, or the format's own ``option``."""
    return "-o" if args.output is not None else option


def _moments(args: argparse.Namespace, option: str, folder: str) -> Iterator[Any]:
    """The preamble of ``--openscenario`` and ``--scenic``: the options checked, the output folder
    checked (UserError for an empty name or a file), the results opened, what they leave unknown
    said on stderr (failed traces, an interrupted run: no moments there), and the moments."""
    from ..dataset.moments import check_output_folder, left_out, moments
    from ..dataset.results_traces import ResultsTraces

    if args.prompt is not None or args.referred is not None:
        raise UserError("--prompt and --referred go with --refav")
    check_output_folder(folder, option)
    source = ResultsTraces.open(args.results, args.dataset)
    for sentence in [] if args.quiet else left_out(source.results, args.results):
        print(f"scenegrep: {sentence}", file=sys.stderr)
    return moments(source.results, source.trace, args.context)


def _openscenario(args: argparse.Namespace) -> int:
    from ..dataset.openscenario_export import write_openscenario

    summary = write_openscenario(_moments(args, _option(args, "--openscenario"), args.openscenario), args.openscenario)
    if not args.quiet:
        print(
            f"scenegrep: {counted(len(summary.files), 'match')} written as OpenSCENARIO 1.3 to {args.openscenario}",
            file=sys.stderr,
        )
        if summary.without_road_network:
            print(
                f"scenegrep: {counted(summary.without_road_network, 'file')} "
                f"{verb(summary.without_road_network, 'have')} no road network: their traces' maps are not "
                "OpenDRIVE (said in each file's FileHeader description)",
                file=sys.stderr,
            )
        if summary.default_size:
            print(
                f"scenegrep: {counted(summary.default_size, 'object')} {verb(summary.default_size, 'lack')} "
                "a labeled length, width or height: written with "
                "their category's default for it (named in each file's FileHeader description)",
                file=sys.stderr,
            )
        if summary.without_trajectory:
            print(
                f"scenegrep: {counted(summary.without_trajectory, 'object')} {verb(summary.without_trajectory, 'be')} "
                "observed at one frame of their window: "
                "an initial pose, no trajectory",
                file=sys.stderr,
            )
    return 0


def _scenic(args: argparse.Namespace) -> int:
    from ..dataset.scenic_export import without_map_counts, write_scenic_programs

    written = write_scenic_programs(_moments(args, _option(args, "--scenic"), args.scenic), args.scenic)
    if not args.quiet:
        for reason, count in without_map_counts(written).items():
            print(
                f"scenegrep: {counted(count, 'program')} without a road map ({reason}): objects placed without roads",
                file=sys.stderr,
            )
        what = counted(len(written), "match")
        print(f"scenegrep: {what} written as Scenic programs to {args.scenic}", file=sys.stderr)
    return 0
