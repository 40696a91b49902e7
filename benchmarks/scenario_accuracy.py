"""Scenario queries on simulated traces: the matrix of queries x simulated programs.

Runs every program of examples/scenarios/ ``--runs`` times in Scenic's Newtonian simulator
(on the map its header names) and queries every trace with every query of examples/queries/
(window m = half the trace). Prints, per query and program, how many runs match and the query
time per trace (median). A program's own query must match all its runs (seed 000's accuracy
scenarios: no false negatives); other cells count traces that satisfy the query too (the test
suite checks those against a brute-force reference).

    python benchmarks/scenario_accuracy.py [--runs 50] [--steps 150] [--seed 6]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from label_agreement import map_of  # noqa: E402

from scenegrep.scenario import load_scenario  # noqa: E402
from scenegrep.synth.simulate import simulate_runs  # noqa: E402

SCENARIOS = REPO / "examples" / "scenarios"
QUERIES = REPO / "examples" / "queries"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=50)
    parser.add_argument("--steps", type=int, default=150)
    parser.add_argument("--seed", type=int, default=6)
    args = parser.parse_args()
    queries = {path.stem: load_scenario(path) for path in sorted(QUERIES.glob("*.scenic"))}
    counts: dict[tuple[str, str], int] = {}
    times: list[float] = []
    programs = sorted(SCENARIOS.glob("*.scenic"))
    for program in programs:
        for trace in simulate_runs(program, map_path=map_of(program), runs=args.runs, steps=args.steps, seed=args.seed):
            for name, query in queries.items():
                start = time.perf_counter()
                matched = query.match(trace, args.steps // 2).matched
                times.append(time.perf_counter() - start)
                counts[name, program.stem] = counts.get((name, program.stem), 0) + int(matched)
        print(f"{program.name}: {args.runs} runs", file=sys.stderr)
    print(f"matching runs out of {args.runs} (rows: queries; columns: simulated programs)")
    print(" " * 32 + "  ".join(p.stem[:12].rjust(12) for p in programs))
    for name in queries:
        print(name[:30].ljust(32) + "  ".join(str(counts[name, p.stem]).rjust(12) for p in programs))
    print(f"query time per trace: median {statistics.median(times) * 1e3:.1f} ms, max {max(times) * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
