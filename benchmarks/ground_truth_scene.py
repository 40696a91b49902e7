"""Ground truth of the scene query from Scenic: false negatives and perturbation rejection rates.

For every program in examples/ground_truth/, samples N scenes with Scenic 3.1.1 on Town01,
matches them (all must match: false negatives are reported), then perturbs the labels: the
program's declared violations (each must reject every scene) and one random feature of one
object per scene by 0.1 m or 0.05 rad (a program with slack may accept some; the rate shows
how tightly the program pins its scenes down).

    python benchmarks/ground_truth_scene.py [--scenes 200] [--seed 0] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import asdict
from pathlib import Path

from scenegrep.synth.ground_truth import check_program

REPO = Path(__file__).resolve().parents[1]
MAP = REPO.parent / "shared" / "maps" / "Town01.xodr"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args()
    rows = []
    header = ("program", "scenes", "false neg.", "violations rejected", "random rejected", "time")
    print(f"{header[0]:26} {header[1]:>6} {header[2]:>10} {header[3]:>22} {header[4]:>16} {header[5]:>7}")
    for program in sorted((REPO / "examples" / "ground_truth").glob("*.scenic")):
        start = time.perf_counter()
        result = check_program(program, args.scenes, MAP, seed=args.seed)
        seconds = time.perf_counter() - start
        rejected = sum(r for r, _ in result.violations.values())
        total = sum(t for _, t in result.violations.values())
        randoms = result.random_rejected
        print(
            f"{result.program:26} {result.scenes:6d} {result.false_negatives:10d} "
            f"{rejected:>10d} / {total:<9d} {randoms[0] / randoms[1]:15.1%} {seconds:6.1f}s"
        )
        rows.append({**asdict(result), "seconds": seconds})
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
