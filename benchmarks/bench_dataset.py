"""Dataset runs: ingest 1,000 synthetic traces of 200 steps, then one scenario query and one SpRE
query over all of them with 1 and 2 local workers and with Ray (PRODUCT.md: under 30 s on 2 cores).

Traces (generated with numpy, replicated and shifted): bench_scenario.py's Fig. 1 pair (an ego
following its lane that changes lanes left past a parked car) over 400 frames at 10 Hz; trace
i is frames [s, s + 200) of it with the shift s = (37 i) mod 200, so the lane change falls at a
different place in each trace (and before the start of some). Every third trace drops the parked
car (the scenario's catalog pruning removes these: it needs two cars for m frames); every fifth
gets a pedestrian standing beside the road (the SpRE ``[[:pedestrian:]]+`` needs one). All traces
share one map (a straight two-lane road), written once as a scenegrep Parquet map.

Queries: Fig. 1 (bench_scenario.program(1)) with m = 100 frames, and ``[[:pedestrian:]]+``.
Measured: ingest wall time (2 workers), then for each query and engine the median wall time of
``--repeat`` complete runs (plan + query + results written): "Ray, cold" starts and stops a local
Ray instance in every run (as ``--engine ray`` without ``--address`` does), "Ray, running" uses one
started before the runs (as a cluster would be); then the number of traces the catalog pruned and
the number matched. Every run must give the same results table as the first (1 worker); the run
stops otherwise.

    python benchmarks/bench_dataset.py [--traces 1000] [--repeat 3] [--no-ray] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from bench_scenario import program, road_map, synthetic_trace  # noqa: E402
from scenegrep.dataset import QuerySpec, RunOptions, open_dataset  # noqa: E402
from scenegrep.dataset.ingest import ingest  # noqa: E402
from scenegrep.dataset.run import run_query  # noqa: E402
from scenegrep.model import LabelTrace, MapSource, ObjectTable, StateTable  # noqa: E402
from scenegrep.model.behaviours import BehaviourLabels  # noqa: E402
from scenegrep.writers.trace_parquet import write_map_parquet, write_trace_parquet  # noqa: E402

STEPS = 200
BASE_FRAMES = 400
WINDOW = 100
SPRE = "[[:pedestrian:]]+"


def generate(folder: Path, count: int) -> None:
    """Write ``count`` traces and their shared map into ``folder`` (see the module docstring)."""
    base = synthetic_trace(1, BASE_FRAMES, seed=0).trace
    map_path = folder / "straight.map.parquet"
    write_map_parquet(road_map(1, 2 * BASE_FRAMES), map_path)
    for i in range(count):
        shift = (37 * i) % (BASE_FRAMES - STEPS)
        trace = base.slice_frames(shift, shift + STEPS)
        if i % 3 == 2:
            trace = trace.select_objects([o for o in trace.objects.id.tolist() if _moves(trace, o)])
        states, objects, labels = trace.states, trace.objects, trace.behaviours
        if i % 5 == 4:
            states, objects, labels = _with_pedestrian(trace)
        trace = LabelTrace.build(
            f"synthetic-{i:04d}",
            trace.frame_index,
            trace.frame_time,
            objects,
            states,
            behaviours=labels,
            map_source=MapSource(str(map_path), "scenegrep-map-parquet"),
        )
        write_trace_parquet(trace, folder / f"synthetic-{i:04d}.parquet")


def _moves(trace: LabelTrace, object_id: str) -> bool:
    """Whether the object moves (the ego; the parked car never does)."""
    rows = trace.states.object == trace.object_index(object_id)
    return bool(np.ptp(trace.states.y[rows]) > 0)


def _with_pedestrian(trace: LabelTrace) -> tuple[StateTable, ObjectTable, BehaviourLabels]:
    """The trace's states, objects and labels plus a pedestrian standing 6 m right of the road
    in every frame, labelled Stationary."""
    n, row = trace.n_frames, trace.n_objects
    extra = StateTable.build(
        frame=np.arange(n), object=np.full(n, row), x=np.full(n, 6.0), y=np.full(n, 20.0), heading=np.zeros(n)
    )
    ours = trace.states.columns()
    states = StateTable(**{name: np.concatenate([ours[name], column]) for name, column in extra.columns().items()})
    objects = ObjectTable.build([*trace.objects.id.tolist(), "ped0"], [*trace.objects.category.tolist(), "pedestrian"])
    labels = trace.behaviours
    stationary = np.zeros((n, len(labels.vocabulary)), dtype=bool)
    stationary[:, labels.vocabulary.index("Stationary")] = True
    return states, objects, BehaviourLabels(labels.vocabulary, np.concatenate([labels.member, stationary]))


def timed_runs(root: Path, spec: QuerySpec, options: RunOptions, repeat: int) -> tuple[float, list[float], object]:
    times, results = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        results = run_query(root, spec, options)
        times.append(time.perf_counter() - start)
    return statistics.median(times), times, results


@contextmanager
def ray_running(start: bool) -> Iterator[None]:
    """A local Ray instance with 2 CPUs for the duration (runs then reuse it), if ``start``."""
    if not start:
        yield
        return
    import ray

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="ERROR")
    try:
        yield
    finally:
        ray.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--traces", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-ray", action="store_true")
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args()

    work = Path(tempfile.mkdtemp(prefix="bench-dataset-"))
    try:
        sources, dataset = work / "sources", work / "dataset"
        sources.mkdir()
        start = time.perf_counter()
        generate(sources, args.traces)
        generated = time.perf_counter() - start
        start = time.perf_counter()
        report = ingest([str(sources)], dataset, jobs=2)
        ingested = time.perf_counter() - start
        assert report.traces == args.traces and not report.failed, report
        print(
            f"generated {args.traces} traces of {STEPS} steps in {generated:.1f} s; ingest (2 workers) {ingested:.1f} s"
        )
        open_dataset(dataset)
        specs = {
            "scenario": QuerySpec.of("scenario", program(1), "fig1.scenic", window=WINDOW),
            "spre": QuerySpec.of("spre", SPRE),
        }
        engines = [("1 worker", RunOptions(jobs=1)), ("2 workers", RunOptions(jobs=2))]
        if not args.no_ray:
            engines += [("Ray, cold", RunOptions(jobs=2, engine="ray")), ("Ray, running", RunOptions(engine="ray"))]
        record: dict[str, object] = {"traces": args.traces, "steps": STEPS, "ingest_s": ingested, "runs": []}
        print(f"{'query':<9} {'engine':<13} {'median s':>9} {'runs s':<22} {'pruned':>6} {'matched':>7} {'failed':>6}")
        for kind, spec in specs.items():
            reference = None
            for label, options in engines:
                with ray_running(label.endswith("running")):
                    median, times, results = timed_runs(dataset, spec, options, args.repeat)
                counts = results.counts()
                table = results.to_arrow()
                if reference is None:
                    reference = table
                elif not table.equals(reference):
                    raise SystemExit(f"{kind} with {label}: results differ from 1 worker")
                runs = " ".join(f"{t:.2f}" for t in times)
                print(
                    f"{kind:<9} {label:<13} {median:>9.2f} {runs:<22} {counts['pruned']:>6} "
                    f"{counts['matched']:>7} {counts['failed']:>6}"
                )
                record["runs"].append({"query": kind, "engine": label, "median_s": median, "times_s": times, **counts})
        if args.json:
            Path(args.json).write_text(json.dumps(record, indent=1))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
