"""The options shared by several commands: one ``add_…`` function per option group, which adds it to
a command's parser, and one function per group that turns the parsed arguments into the Python
API's option objects (checked: a bad value is a :class:`~scenegrep.errors.UserError`).

Groups and who has them:

- ``--map MAP``: the road map for traces without one (scene, scenario, coverage, label);
- tolerances, ``--tolerance-profile NAME`` and ``--tolerance-position/-heading/-speed``
  (scene, scenario, coverage) -> :class:`scenegrep.scene.Tolerance`;
- ``--unknown-layers permissive|strict`` (scene, scenario, coverage, label, ingest) ->
  :class:`scenegrep.model.layers.UnknownLayers`, and its report on stderr;
- the results table, ``-o/--output FILE`` and ``--csv`` (scene, scenario, spre);
- datasets, ``--dataset``, ``-j/--jobs``, ``--engine``, ``--address``, ``--resume`` (scene,
  scenario, spre, coverage) -> :class:`scenegrep.dataset.run.RunOptions`; ``-j/--jobs`` alone
  (ingest, serve);
- ROS 2 bags and MCAP files, ``--topics``, ``--frame-topic``, ``--rate``, ``--map-frame``,
  ``--ego-frame``, ``--ego-size`` (info, scene, scenario, spre, label) ->
  :class:`scenegrep.readers.ros.options.BagOptions`, put in force by :func:`bag_options_applied`;
- live input, ``--follow FILE``, ``--idle-timeout S``, ``--latency`` (scenario, spre);
- output files (``-o``, ``--html``, ``--png`` of show, report, coverage): :func:`check_output_file`
  refuses a wrong suffix or a directory before any work.

Nothing here is imported at ``--help`` time beyond argparse: the API's modules are imported by the
functions that build their objects.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..wording import article

MAP_HELP = (
    "road map for traces without one (e.g. an .xodr or a Lanelet2 .osm file); a trace with its own map and --map "
    "is an error"
)

UNKNOWN_LAYERS = ("permissive", "strict")
"""The choices (as :data:`scenegrep.model.layers.MODES`, repeated so ``--help`` imports nothing)."""


def add_map_argument(parser: argparse.ArgumentParser) -> None:
    """``--map MAP``, the road map for traces without one."""
    parser.add_argument("--map", metavar="MAP", help=MAP_HELP)


def add_tolerance_arguments(parser: argparse.ArgumentParser) -> None:
    """``--tolerance-profile`` and the three tolerances of the Scenic query commands."""
    from ..scene.profiles import PROFILES

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
    from ..scene.profiles import tolerance_of as profile_tolerance

    return profile_tolerance(
        args.tolerance_profile,
        position=args.tolerance_position,
        heading=args.tolerance_heading,
        speed=args.tolerance_speed,
    )


def scenic_query_options(args: argparse.Namespace) -> dict[str, Any]:
    """The tolerance and unknown-layers options as :class:`~scenegrep.dataset.QuerySpec` options
    (the tolerances checked by :func:`tolerance_of`)."""
    tolerance_of(args)
    return {
        "tolerance_profile": args.tolerance_profile,
        "tolerance_position": args.tolerance_position,
        "tolerance_heading": args.tolerance_heading,
        "tolerance_speed": args.tolerance_speed,
        "unknown_layers": args.unknown_layers,
    }


def add_unknown_layers_argument(parser: argparse.ArgumentParser) -> None:
    """``--unknown-layers permissive|strict``."""
    parser.add_argument(
        "--unknown-layers",
        choices=UNKNOWN_LAYERS,
        default=None,
        help="how to treat map layers the map's format does not publish (nuScenes has no crosswalks, "
        "AV2 no sidewalks): as everywhere (permissive) or empty (strict); without it a query or label "
        "rule that needs one is an error; likewise a sidewalk or crosswalk direction the map does not give "
        "(only OpenDRIVE maps give it): any heading (permissive) or none (strict). The number of decisions "
        "the choice affected is printed on stderr",
    )


def unknown_layers_of(args: argparse.Namespace) -> Any:
    """The :class:`~scenegrep.model.layers.UnknownLayers` the options give."""
    from ..model.layers import UnknownLayers

    return UnknownLayers(args.unknown_layers)


def report_unknown_layers(choice: Any) -> None:
    """Print an :class:`~scenegrep.model.layers.UnknownLayers` choice and the decisions it affected
    on stderr (nothing without a choice)."""
    line = choice.report()
    if line is not None:
        print(f"scenegrep: {line}", file=sys.stderr)


def add_results_arguments(parser: argparse.ArgumentParser) -> None:
    """``-o/--output FILE`` and ``--csv``: the results table of a query, over files or a dataset."""
    group = parser.add_argument_group("results table (also over files)")
    group.add_argument("-o", "--output", metavar="FILE", help="also write the results table to this Parquet file")
    group.add_argument("--csv", action="store_true", help="print the results table as CSV")


def add_jobs_argument(parser: Any, what: str = "") -> None:
    """``-j/--jobs N``, the worker processes (of ``what``)."""
    parser.add_argument("-j", "--jobs", type=int, metavar="N", help=f"worker processes{what} (default: all cores)")


def add_dataset_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of a run over an ingested dataset."""
    group = parser.add_argument_group("datasets (scenegrep ingest)")
    group.add_argument("--dataset", metavar="DATASET", help="query every trace of an ingested dataset")
    add_jobs_argument(group)
    group.add_argument("--engine", choices=["local", "ray"], default="local", help="local processes or Ray")
    group.add_argument("--address", metavar="ADDR", help="Ray cluster address (default: start a local Ray)")
    group.add_argument("--resume", action="store_true", help="continue an interrupted run of the same query")


def reject_dataset_only(args: argparse.Namespace) -> None:
    """Dataset options given without --dataset are user errors."""
    if args.resume:
        raise UserError("--resume needs --dataset")
    if args.engine != "local" or args.jobs is not None or args.address:
        raise UserError("--jobs, --engine and --address need --dataset")


def run_options_of(args: argparse.Namespace) -> Any:
    """The :class:`~scenegrep.dataset.run.RunOptions` of a run over ``--dataset`` (a progress bar
    unless the command is quiet; the run shows it only on a terminal)."""
    from ..dataset.run import RunOptions

    return RunOptions(args.jobs, args.engine, args.address, args.resume, getattr(args, "map", None), not args.quiet)


def add_bag_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ROS 2 bag and MCAP inputs."""
    group = parser.add_argument_group("ROS 2 bags and MCAP files")
    group.add_argument(
        "--topics", metavar="T1,T2", help="topics to read (default: every supported one; /tf is always read)"
    )
    group.add_argument(
        "--frame-topic", metavar="TOPIC", help="one frame per message of TOPIC (default: the first box topic)"
    )
    group.add_argument(
        "--rate", type=float, metavar="HZ", help="frames at HZ instead, each the latest boxes of its window"
    )
    group.add_argument(
        "--map-frame", default="map", metavar="FRAME", help="the frame positions are given in (default: map)"
    )
    group.add_argument("--ego-frame", default="base_link", metavar="FRAME", help="the ego's frame (default: base_link)")
    group.add_argument(
        "--ego-size",
        metavar="L,W,H",
        help="the ego's length, width and height in metres (tf and odometry carry none: without it, a query "
        "that needs the ego's extent is an error)",
    )


def bag_options_of(args: argparse.Namespace) -> Any:
    """The :class:`~scenegrep.readers.ros.options.BagOptions` the options give (None for a command
    without them). UserError when options other than the defaults go with ``--dataset``: its
    traces were read from their bags at ingest, so the options could not apply."""
    if not hasattr(args, "ego_frame"):
        return None
    from ..readers.ros.options import BagOptions

    topics = tuple(t.strip() for t in (args.topics or "").split(",") if t.strip())
    ego_size = None if args.ego_size is None else _ego_size(args.ego_size)
    options = BagOptions(topics, args.frame_topic, args.rate, args.map_frame, args.ego_frame, ego_size)
    if getattr(args, "dataset", None) is not None and options != BagOptions():
        raise UserError(
            "--topics, --frame-topic, --rate, --map-frame, --ego-frame and --ego-size apply when bags are read; a "
            "dataset's traces were read at ingest (with the defaults): query the bags as files instead"
        )
    return options


def _ego_size(text: str) -> tuple[float, ...]:
    """``--ego-size L,W,H`` as three floats (checked by :class:`BagOptions`); UserError if not numbers."""
    from ..readers.ros.options import check_ego_size

    parts = text.split(",")
    try:
        size = tuple(float(part) for part in parts[:4])
    except ValueError:
        raise UserError(f"--ego-size {text[:40]!r}: give LENGTH,WIDTH,HEIGHT in metres, e.g. 4.9,1.9,1.5") from None
    check_ego_size(size)
    return size


@contextlib.contextmanager
def bag_options_applied(args: argparse.Namespace) -> Iterator[None]:
    """Read bags with the command's options (:func:`bag_options_of`) within the block."""
    options = bag_options_of(args)
    if options is None:
        yield
        return
    from ..readers.ros.options import using

    with using(options):
        yield


def add_live_arguments(parser: argparse.ArgumentParser) -> None:
    """``--follow``, ``--idle-timeout`` and ``--latency`` of the online commands."""
    parser.add_argument(
        "--follow", metavar="FILE", help="follow an MCAP file as it is written, like tail -f (implies --online)"
    )
    parser.add_argument(
        "--idle-timeout",
        type=float,
        metavar="S",
        help="with --follow: stop after S seconds without new bytes (default: at the writer's end, Ctrl-C or SIGTERM)",
    )
    parser.add_argument(
        "--latency", action="store_true", help="print each frame's latency on stderr at the end (median, p99)"
    )


def check_live_arguments(args: argparse.Namespace) -> None:
    """UserError for ``--idle-timeout`` without ``--follow`` or not a positive number of seconds."""
    if args.idle_timeout is None:
        return
    if args.follow is None:
        raise UserError("--idle-timeout S needs --follow FILE")
    if not math.isfinite(args.idle_timeout) or args.idle_timeout <= 0:
        raise UserError(f"--idle-timeout: {args.idle_timeout} is not a positive number of seconds")


def check_output_file(option: str, path: str, suffixes: Sequence[str]) -> str:
    """The suffix (lowercase, no dot) of the file ``path`` given to ``option``, checked before any
    work: one of ``suffixes`` (``.png``; any case), and not a directory (UserError otherwise)."""
    suffix = Path(path).suffix.lower()
    if suffix not in suffixes:
        listed = suffixes[0] if len(suffixes) == 1 else f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"
        raise UserError(f"{option} {path}: write {article(suffixes[0][1:].upper())} {listed} file")
    if Path(path).is_dir():
        raise UserError(f"{option} {path}: a directory; name the file to write")
    return suffix[1:]
