"""``scenegrep evaluate PREDICTIONS GROUND_TRUTH``: RefAV's timestamp-level and log-level
balanced accuracy of a submission (:mod:`scenegrep.dataset.refav_score`).

Both files are RefAV JSON (:mod:`scenegrep.dataset.refav_format`, what ``scenegrep export
--refav OUT.json`` writes); a pickle is refused. ``--av2 DIR`` (the AV2 sensor split holding
``DIR/<log id>/map``) adds RefAV's drivable-area filter. Output: the two balanced accuracies
(means over prompts) and each prompt's counts; ``--json`` as one JSON Lines record. Exit codes: 0
evaluated, 2 user error.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from ..errors import UserError
from ..wording import counted, verb


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "evaluate",
        help="score a RefAV scenario-mining submission: timestamp- and log-level balanced accuracy",
        description="Compute RefAV's timestamp-level and log-level balanced accuracy (per prompt, then the mean "
        "over prompts) of PREDICTIONS against GROUND_TRUTH, both RefAV JSON files at the 2 Hz evaluation "
        "timestamps. A submission with boxes is scored on the boxes within --max-range metres of the ego and, "
        "with --av2, within 5 m of the log's drivable area, as RefAV's scorer does.",
    )
    parser.add_argument("predictions", metavar="PREDICTIONS", help="RefAV JSON of the predictions")
    parser.add_argument("ground_truth", metavar="GROUND_TRUTH", help="RefAV JSON of the ground truth")
    parser.add_argument(
        "--av2", metavar="DIR", help="the AV2 sensor split of the logs (DIR/<log id>/map): drivable area"
    )
    parser.add_argument("--max-range", type=float, default=50.0, metavar="M", help="evaluation range (m; default 50)")
    parser.add_argument("--json", action="store_true", help="print the scores as JSON Lines (one object)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dataset.refav_format import read_sequences
    from ..dataset.refav_score import av2_drivable_areas, evaluate

    if not (math.isfinite(args.max_range) and args.max_range > 0):
        raise UserError(f"--max-range {args.max_range}: give a positive number of metres")
    predictions = read_sequences(args.predictions)
    truth = read_sequences(args.ground_truth)
    drivable = av2_drivable_areas(args.av2) if args.av2 is not None else None
    result = evaluate(predictions, truth, args.max_range, drivable)
    document = {
        "timestamp_balanced_accuracy": result.timestamp_ba,
        "log_balanced_accuracy": result.log_ba,
        "prompts": [
            {"prompt": p.prompt, **{level: _counts(getattr(p, level)) for level in ("timestamp", "log")}}
            for p in result.prompts
        ],
        "boxes_filtered": result.filtered,
        "max_range_m": args.max_range,
        "drivable_area_filter": result.filtered and drivable is not None,
        "unscored_prediction_pairs": result.unscored_pairs,
    }
    if args.json:
        from ..json_lines import write

        write(document)
        return 0
    print(f"timestamp-level balanced accuracy: {result.timestamp_ba:.4f}")
    print(f"log-level balanced accuracy: {result.log_ba:.4f}")
    for scored in document["prompts"]:
        print(f"  {scored['prompt']}: timestamp {_line(scored['timestamp'])}; log {_line(scored['log'])}")
    if result.filtered:
        area = "and 5 m of the drivable area" if drivable is not None else "(no drivable-area filter: give --av2 DIR)"
        print(f"scenegrep: boxes scored within {args.max_range:g} m of the ego {area}", file=sys.stderr)
    if result.unscored_pairs:
        print(
            f"scenegrep: {counted(result.unscored_pairs, 'predicted (log, prompt) pair')} "
            f"{verb(result.unscored_pairs, 'be')} not in the ground truth",
            file=sys.stderr,
        )
    return 0


def _counts(counts: Any) -> dict[str, Any]:
    return {
        "balanced_accuracy": counts.balanced_accuracy(),
        "tp": counts.tp,
        "fp": counts.fp,
        "fn": counts.fn,
        "tn": counts.tn,
    }


def _line(c: dict[str, Any]) -> str:
    return f"{c['balanced_accuracy']:.4f} (TP {c['tp']} FP {c['fp']} FN {c['fn']} TN {c['tn']})"
