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
import sys
from typing import Any

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
    from ..dataset.refav_score import evaluate_files

    result = evaluate_files(args.predictions, args.ground_truth, args.max_range, args.av2)
    document = result.document()
    if args.json:
        from ..json_lines import write

        write(document)
        return 0
    print(f"timestamp-level balanced accuracy: {result.timestamp_ba:.4f}")
    print(f"log-level balanced accuracy: {result.log_ba:.4f}")
    for scored in document["prompts"]:
        print(f"  {scored['prompt']}: timestamp {_line(scored['timestamp'])}; log {_line(scored['log'])}")
    if result.filtered:
        area = "and 5 m of the drivable area" if result.drivable_area else "(no drivable-area filter: give --av2 DIR)"
        print(f"scenegrep: boxes scored within {args.max_range:g} m of the ego {area}", file=sys.stderr)
    if result.unscored_pairs:
        print(
            f"scenegrep: {counted(result.unscored_pairs, 'predicted (log, prompt) pair')} "
            f"{verb(result.unscored_pairs, 'be')} not in the ground truth",
            file=sys.stderr,
        )
    return 0


def _line(c: dict[str, Any]) -> str:
    return f"{c['balanced_accuracy']:.4f} (TP {c['tp']} FP {c['fp']} FN {c['fn']} TN {c['tn']})"
