"""The options of ROS 2 bag and MCAP inputs, shared by the commands that read inputs.

``--topics``, ``--frame-topic``, ``--rate``, ``--map-frame`` and ``--ego-frame`` (see
:class:`scenegrep.readers.ros.options.BagOptions`) are added to a command's parser by
:func:`add_arguments`; :func:`applied` puts them in force while the command runs.
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterator
from typing import Any

from ..errors import UserError

COMMANDS_WITH_BAGS = ("info", "scene", "scenario", "spre", "label")
"""The commands whose inputs may be bags."""


def add_arguments(parser: Any) -> None:
    """Add the bag options to a command's parser."""
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


@contextlib.contextmanager
def applied(args: argparse.Namespace) -> Iterator[None]:
    """Read bags with the command's options within the block (nothing to do for a command
    without them). UserError when options other than the defaults go with ``--dataset``: its
    traces were read from their bags at ingest, so the options could not apply."""
    if not hasattr(args, "ego_frame"):
        yield
        return
    from ..readers.ros.options import BagOptions, using

    topics = tuple(t.strip() for t in (args.topics or "").split(",") if t.strip())
    options = BagOptions(topics, args.frame_topic, args.rate, args.map_frame, args.ego_frame)
    if getattr(args, "dataset", None) is not None and options != BagOptions():
        raise UserError(
            "--topics, --frame-topic, --rate, --map-frame and --ego-frame apply when bags are read; a dataset's "
            "traces were read at ingest (with the defaults): query the bags as files instead"
        )
    with using(options):
        yield
