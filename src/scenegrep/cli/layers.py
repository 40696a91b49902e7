"""``--unknown-layers``: the command-line choice for map layers a map does not publish, shared by
the commands that read road maps (scene, scenario, label, ingest), and its report on stderr."""

from __future__ import annotations

import argparse
import sys
from typing import Any

MODES = ("permissive", "strict")
"""The choices (as :data:`scenegrep.model.layers.MODES`, repeated so ``--help`` imports nothing)."""


def add_unknown_layers_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--unknown-layers permissive|strict``."""
    parser.add_argument(
        "--unknown-layers",
        choices=MODES,
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
    """Print the choice and the decisions it affected on stderr (nothing without a choice)."""
    line = choice.report()
    if line is not None:
        print(f"scenegrep: {line}", file=sys.stderr)
