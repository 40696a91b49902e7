"""Scenic scenario queries (seed 000): query time against trace duration and number of objects (Fig. 5).

Programs: seed 000's Fig. 1 replicated k times (Appendix 0.C.2: "we incrementally added two
agents engaging in the same behaviour"): pair j is a car ``egoJ`` (pair 0 is ``ego``) that
follows its lane and, once its own parked car ``obstacleJ`` is closer than Range(1, 15) m,
changes lanes to the left and follows the new lane. Pair 0 is Fig. 1 itself (``on visible
ego.lane``); pair j > 0 puts its obstacle ``on egoJ.lane`` (``visible`` always means visible
from the ego). Each pair has its own behaviour reading its obstacle as a global, as Fig. 1
does: a behaviour *parameter* cannot carry the obstacle, since Scenic evaluates the arguments
of ``new Car with behavior B(obstacleJ)`` before ``obstacleJ`` (placed on ``egoJ.lane``) exists.

Traces (synthetic, built with numpy, no simulation): a straight road running north with two
adjacent northbound lanes per pair, 3.5 m wide (the ego's lane and its left neighbour); 10 Hz.
``egoJ`` drives north in the middle of its lane at 10 m/s (heading 0); ``obstacleJ`` is parked
on that lane so that the ego is 25 m behind it at frame max(0, N/2 - 30); the ego is labelled
FollowLane until the centre distance drops below 12 m, then LaneChange while it moves into the
left lane over 20 frames, then FollowLane to the end; obstacles are Stationary. All objects are
class ``car``, ids are a random permutation of ``veh0..veh{2k-1}`` (object rows sorted by id),
and the trace names no ego, so the whole correspondence is unknown. Window m = N // 2.

Measured: the wall time of ``ScenarioQuery.match`` alone. The program is compiled once per
size and the map built once, outside the timing. Per trace: one untimed call checks the answer
(the first one of a size also builds the lazy automata: the warm-up), then the median of
``--repeat`` timed calls after one more warm-up call (timing.py's ``median_seconds``; a single
timed call when the checking call took over a second). Cells give the mean and std over
``--traces`` traces, each from its own seed. Every call is cut at ``--timeout`` s (10 s, seed
000's limit): such a trace counts as a timeout, and a size whose every trace times out ends
part (b). (a) Duration: N = 20..100 frames with one pair (Fig. 5 left), then N = 1,000, 6,000
and 36,000 frames (3 traces, at most 3 runs each); the time per frame shows linearity.
(b) Objects: 2..32 objects (1..16 pairs) at N = 100, m = 50 (Fig. 5 right).

Checks (a failure stops the run): every trace must match, every correspondence found must map
each ``egoJ``/``obstacleJ`` to the ego and obstacle of one generated pair (distinct pairs; pairs
are identical up to their lane, so a permutation of the pairs is also a true answer; "exact"
counts the traces answered with the generated pairing itself) and every reported window start
must have each obstacle ahead of its ego on the ego's lane (pair 0's within 50 m); with up to
three pairs, an untimed ``find_all`` call per trace must find exactly the k! pair permutations.

Targets: 8 objects under 0.1 s (seed 000 timed out at 10 s), 16 objects under 1 s, 36,000
frames under 2 s (each for the slowest trace), time linear in duration (mean time per frame at
36,000 frames at most 1.5 x that at 1,000 frames).

``--pair-spacing`` (default 7 m: all pairs on one road, as above) moves the pairs apart in part
(b): the guard's Range(1, 15) then no longer holds for an ego and another pair's obstacle, which
the default layout leaves to the initial-scene check (``obstacleJ on egoJ.lane``).

    python benchmarks/bench_scenario.py [--repeat 5] [--traces 10] [--quick] [--timeout 10]
        [--pair-spacing 7] [--seed 0] [--json results.json]

``--quick`` (N up to 100, up to 8 objects, 3 traces, 3 repeats) is a smoke run of a few seconds;
the full run takes about 40 seconds.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import statistics
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from timing import median_seconds  # noqa: E402
from scenegrep.model import Area, BehaviourLabels, Lane, LabelTrace, ObjectTable, RoadMap, StateTable  # noqa: E402
from scenegrep.model.roadmap import LaneNeighbour  # noqa: E402
from scenegrep.scenario import ScenarioOptions, ScenarioQuery, compile_scenario  # noqa: E402

SPEED = 10.0
"""Ego speed (m/s)."""
DT = 0.1
"""Frame period (s)."""
LANE_WIDTH = 3.5
PAIR_SPACING = 2 * LANE_WIDTH
"""Default lateral distance (m) between pairs: pair j's ego lane is centred on x = 7 j, so all lanes form one road."""
APPROACH_GAP = 25.0
"""The ego is this far (m, centre to centre) behind its obstacle at frame max(0, N/2 - 30)."""
CHANGE_GAP = 12.0
"""The ego starts changing lanes when the centre distance drops below this (m)."""
CHANGE_FRAMES = 20
VISIBLE = 50.0
"""Scenic's default visible distance (m): pair 0's obstacle must lie within it."""
CAR_LENGTH, CAR_WIDTH = 4.5, 2.0
DURATIONS = (20, 40, 60, 80, 100)
LONG_DURATIONS = (1_000, 6_000, 36_000)
PAIRS = (1, 2, 3, 4, 8, 16)
OBJECT_FRAMES = 100
VOCABULARY = ("FollowLane", "LaneChange", "Stationary")
TARGET_8_OBJECTS_S = 0.1
TARGET_16_OBJECTS_S = 1.0
TARGET_36K_FRAMES_S = 2.0
LINEARITY = 1.5


def pair_names(j: int) -> tuple[str, str]:
    return ("ego" if j == 0 else f"ego{j}"), f"obstacle{j}"


def program(k: int) -> str:
    """Fig. 1 with k pairs (see the module docstring)."""
    lines = ["model scenic.simulators.newtonian.driving_model", ""]
    for j in range(k):
        _, obstacle = pair_names(j)
        lines += [
            f"behavior AvoidBehavior{j}():",
            "    try:",
            "        do FollowLaneBehavior(target_speed=10)",
            f"    interrupt when (distance from self to {obstacle}) < Range(1, 15):",
            "        do LaneChangeBehavior(laneSectionToSwitch=self.laneSection._laneToLeft, target_speed=10)",
            "        do FollowLaneBehavior(target_speed=10)",
            "",
        ]
    for j in range(k):
        ego, obstacle = pair_names(j)
        lines.append(f"{ego} = new Car with behavior AvoidBehavior{j}()")
        lines.append(f"{obstacle} = new Car on {'visible ' if j == 0 else ''}{ego}.lane")
    return "\n".join(lines) + "\n"


def road_map(k: int, length: float, spacing: float = PAIR_SPACING) -> RoadMap:
    """2k northbound lanes from y = -length/2 to length/2: pair j's ego lane ``E{j}`` centred on
    x = spacing * j and its left neighbour ``L{j}`` on x = spacing * j - 3.5. With the default
    spacing the lanes are all adjacent (``L{j}`` is right of ``E{j-1}``), one road; wider, the
    pairs' roads are apart."""
    half, w = length / 2, LANE_WIDTH / 2
    adjacent = math.isclose(spacing, PAIR_SPACING)
    lanes = []
    for j in range(k):
        x = spacing * j
        lanes.append(
            Lane(
                f"E{j}",
                shapely.box(x - w, -half, x + w, half),
                np.array([[x, -half], [x, half]]),
                road="road",
                left=LaneNeighbour(f"L{j}", True),
                right=LaneNeighbour(f"L{j + 1}", True) if adjacent and j + 1 < k else None,
            )
        )
        x -= LANE_WIDTH
        lanes.append(
            Lane(
                f"L{j}",
                shapely.box(x - w, -half, x + w, half),
                np.array([[x, -half], [x, half]]),
                road="road",
                left=LaneNeighbour(f"E{j - 1}", True) if adjacent and j > 0 else None,
                right=LaneNeighbour(f"E{j}", True),
            )
        )
    surface = shapely.union_all([shapely.box(spacing * j - 3 * w, -half, spacing * j + w, half) for j in range(k)])
    road = Area("road", surface, tuple(x.id for x in lanes))
    return RoadMap(f"straight-{2 * k}-lanes", tuple(lanes), roads=(road,))


@dataclass
class Synthetic:
    """A generated trace, the label ids of each pair (ego, obstacle), and where things are."""

    trace: LabelTrace
    pairs: list[tuple[str, str]]
    ego_y: np.ndarray
    """(frames,) the egos' y (all egos move alike)."""
    obstacle_y: float
    change_start: int
    """First LaneChange frame (may be >= N)."""


def synthetic_trace(k: int, n: int, seed: int, spacing: float = PAIR_SPACING) -> Synthetic:
    """The trace of k pairs over n frames (see the module docstring)."""
    rng = np.random.default_rng(seed)
    frames = np.arange(n)
    ego_y = SPEED * DT * frames
    close = max(0, n // 2 - 30)
    obstacle_y = float(ego_y[close] + APPROACH_GAP) if close < n else APPROACH_GAP
    step = SPEED * DT
    change_start = int(math.floor((obstacle_y - CHANGE_GAP) / step)) + 1  # first frame with gap < 12 m
    progress = np.clip((frames - change_start + 1) / CHANGE_FRAMES, 0.0, 1.0)  # 1/20 .. 1 during the change
    ego_dx = -LANE_WIDTH * progress
    changing = (frames >= change_start) & (frames < change_start + CHANGE_FRAMES)

    n_objects = 2 * k
    numbers = rng.permutation(n_objects)
    true_ids = [f"veh{v}" for v in numbers]  # generated object i (ego j = 2j, obstacle j = 2j + 1)
    table_ids = sorted(true_ids)
    row = np.array([table_ids.index(v) for v in true_ids])
    pair = np.arange(n_objects) // 2
    is_ego = np.arange(n_objects) % 2 == 0
    lane_x = spacing * pair

    frame = np.repeat(frames, n_objects)
    generated = np.tile(np.arange(n_objects), n)
    ego_row = is_ego[generated]
    x = lane_x[generated] + np.where(ego_row, ego_dx[frame], 0.0)
    y = np.where(ego_row, ego_y[frame], obstacle_y)
    vx = np.where(ego_row & changing[frame], -LANE_WIDTH / (CHANGE_FRAMES * DT), 0.0)
    vy = np.where(ego_row, SPEED, 0.0)
    states = StateTable.build(
        frame=frame,
        object=row[generated],
        x=x,
        y=y,
        heading=np.zeros(len(frame)),
        length=np.full(len(frame), CAR_LENGTH),
        width=np.full(len(frame), CAR_WIDTH),
        vx=vx,
        vy=vy,
    )
    member = np.zeros((len(frame), len(VOCABULARY)), dtype=bool)
    member[:, 0] = ego_row & ~changing[frame]
    member[:, 1] = ego_row & changing[frame]
    member[:, 2] = ~ego_row
    objects = ObjectTable.build(table_ids, ["car"] * n_objects)
    trace = LabelTrace.build(
        f"fig1x{k}-N{n}-seed{seed}",
        frames,
        frames * DT,
        objects,
        states,
        behaviours=BehaviourLabels(VOCABULARY, member),
    )
    pairs = [(true_ids[2 * j], true_ids[2 * j + 1]) for j in range(k)]
    return Synthetic(trace, pairs, ego_y, obstacle_y, change_start)


def verify(query: ScenarioQuery, data: Synthetic, window: int, roads: RoadMap, find_all: bool) -> int:
    """Check the answer (see the module docstring); the number of correspondences found that are the
    generated one exactly (not a permutation of the pairs). Raises AssertionError on a wrong answer."""
    trace, k = data.trace, len(data.pairs)
    options = ScenarioOptions(find_all=find_all)
    result = query.match(trace, window, road_map=roads, options=options)
    if not result.matched:
        raise AssertionError(f"{trace.name}: no match; {result.why_not()}")
    expected = math.factorial(k) if find_all else 1
    if len(result.matches) != expected:
        raise AssertionError(f"{trace.name}: {len(result.matches)} correspondences found, expected {expected}")
    pair_of_ego = {e: p for p, (e, _) in enumerate(data.pairs)}
    exact = 0
    for found in result.matches:
        corr = found.correspondence
        used = []
        for j in range(k):
            ego, obstacle = pair_names(j)
            p = pair_of_ego.get(corr.get(ego, ""))
            if p is None or corr.get(obstacle) != data.pairs[p][1]:
                raise AssertionError(f"{trace.name}: {ego}/{obstacle} -> {corr.get(ego)}/{corr.get(obstacle)}")
            used.append(p)
        if sorted(used) != list(range(k)):
            raise AssertionError(f"{trace.name}: pairs used twice in {corr}")
        exact += used == list(range(k))
        starts = np.asarray(found.starts)
        if len(starts) == 0 or starts.min() < 0 or starts.max() > trace.n_frames - window:
            raise AssertionError(f"{trace.name}: bad window starts {starts}")
        gap = data.obstacle_y - data.ego_y[starts]
        lateral = np.abs(LANE_WIDTH * np.clip((starts - data.change_start + 1) / CHANGE_FRAMES, 0, 1))
        if (gap <= 0).any() or (lateral > LANE_WIDTH / 2).any() or (gap > VISIBLE).any():
            raise AssertionError(f"{trace.name}: a start in {starts} has an obstacle off its ego's lane or unseen")
    return exact


class QueryTimeout(Exception):
    """A query call ran past ``--timeout``."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`QueryTimeout` in the block after ``seconds`` of wall time (SIGALRM)."""

    def expire(signum, frame):
        raise QueryTimeout

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@dataclass
class Cell:
    """One size: per trace its time (s), or None when it timed out."""

    label: str
    objects: int
    frames: int
    window: int
    seconds: list[float | None]
    exact: int
    runs: list[int]

    @property
    def done(self) -> list[float]:
        return [s for s in self.seconds if s is not None]

    @property
    def timeouts(self) -> int:
        return len(self.seconds) - len(self.done)

    @property
    def mean(self) -> float:
        return statistics.fmean(self.done) if self.done else math.inf

    @property
    def std(self) -> float:
        return statistics.stdev(self.done) if len(self.done) > 1 else 0.0

    @property
    def worst(self) -> float:
        return math.inf if self.timeouts or not self.done else max(self.done)

    def row(self) -> dict:
        return {
            "case": self.label,
            "objects": self.objects,
            "frames": self.frames,
            "window": self.window,
            "mean_s": self.mean if self.done else None,
            "std_s": self.std if self.done else None,
            "per_trace_s": self.seconds,
            "timed_runs_per_trace": self.runs,
            "timeouts": self.timeouts,
            "exact_correspondences": self.exact,
        }


def measure(
    label: str, k: int, n: int, traces: int, repeat: int, seed: int, timeout: float, spacing: float = PAIR_SPACING
) -> Cell:
    """Compile the k-pair program, then time ``match`` on ``traces`` traces of n frames (see the
    module docstring). After a cut at ``timeout`` the program is compiled afresh: the cut may
    have come in the middle of extending an automaton."""
    text = program(k)
    query = compile_scenario(text, f"fig1x{k}.scenic")
    window = n // 2
    roads = road_map(k, 2 * SPEED * DT * n + 4 * APPROACH_GAP, spacing)
    cell = Cell(label, 2 * k, n, window, [], 0, [])
    for t in range(traces):
        data = synthetic_trace(k, n, seed + t, spacing)
        try:
            start = time.perf_counter()
            with time_limit(timeout):
                cell.exact += verify(query, data, window, roads, find_all=False)
            first = time.perf_counter() - start
            if k <= 3:
                with time_limit(timeout):
                    verify(query, data, window, roads, find_all=True)
            runs = repeat if first < 1.0 else 1
            with time_limit(timeout * (runs + 1)):
                seconds = median_seconds(lambda q=query, d=data: q.match(d.trace, window, road_map=roads), runs)
            cell.seconds.append(seconds)
            cell.runs.append(runs)
        except QueryTimeout:
            cell.seconds.append(None)
            cell.runs.append(0)
            query = compile_scenario(text, f"fig1x{k}.scenic")
    return cell


def header() -> str:
    return (
        f"{'objects':>7s} {'frames N':>8s} {'window m':>8s} {'traces':>6s} {'mean s':>9s} {'std s':>9s} "
        f"{'min..max s':>19s} {'us/frame':>9s} {'exact':>6s} {'runs':>5s} {'timeouts':>8s}"
    )


def line(cell: Cell) -> str:
    if not cell.done:
        return (
            f"{cell.objects:7d} {cell.frames:8d} {cell.window:8d} {len(cell.seconds):6d} "
            f"{'every trace timed out':>49s} {'':>6s} {'':>5s} {cell.timeouts:8d}"
        )
    return (
        f"{cell.objects:7d} {cell.frames:8d} {cell.window:8d} {len(cell.seconds):6d} {cell.mean:9.4f} "
        f"{cell.std:9.4f} {min(cell.done):9.4f}..{max(cell.done):<8.4f} {cell.mean / cell.frames * 1e6:9.1f} "
        f"{cell.exact:3d}/{len(cell.done):<2d} {min(r for r in cell.runs if r):5d} {cell.timeouts:8d}"
    )


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def seconds_text(cell: Cell) -> str:
    if not cell.done:
        return "every trace timed out"
    text = f"mean {cell.mean:.4f} s, max {max(cell.done):.4f} s"
    return text + (f", {cell.timeouts} of {len(cell.seconds)} timed out" if cell.timeouts else "")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, help="timed runs per trace (default 5; 3 with --quick)")
    parser.add_argument("--traces", type=int, help="traces per size (default 10; 3 with --quick)")
    parser.add_argument("--quick", action="store_true", help="N up to 100, up to 8 objects, 3 traces: a smoke run")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds per query call (default 10, seed 000's)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first trace of each size")
    parser.add_argument(
        "--pair-spacing",
        type=float,
        default=PAIR_SPACING,
        help="metres between the pairs' ego lanes in part (b) (default 7: one road; over 15 + 3.5 no ego is within "
        "the guard's 15 m of another pair's obstacle)",
    )
    parser.add_argument("--json", type=Path, help="also write the results as JSON here")
    args = parser.parse_args()
    if args.pair_spacing < PAIR_SPACING:
        parser.error(f"--pair-spacing must be at least {PAIR_SPACING:g} m (two lanes)")
    repeat = args.repeat or (3 if args.quick else 5)
    traces = args.traces or (3 if args.quick else 10)
    long_durations = () if args.quick else LONG_DURATIONS
    pairs = tuple(k for k in PAIRS if 2 * k <= 8) if args.quick else PAIRS
    start = time.perf_counter()
    print(
        f"scenario query (seed 000 Fig. 1 x k pairs): {traces} traces per size, median of {repeat} timed runs "
        f"per trace, calls cut at {args.timeout:g} s\n"
    )

    print("(a) duration, 2 objects (Fig. 5 left), window m = N // 2")
    print(header())
    durations = []
    for n in DURATIONS:
        durations.append(measure("duration", 1, n, traces, repeat, args.seed, args.timeout))
        print(line(durations[-1]), flush=True)
    for n in long_durations:
        cell = measure("long duration", 1, n, min(traces, 3), min(repeat, 3), args.seed, args.timeout)
        durations.append(cell)
        print(line(cell), flush=True)

    print(
        f"\n(b) objects, N = {OBJECT_FRAMES}, m = {OBJECT_FRAMES // 2} (Fig. 5 right), "
        f"pairs {args.pair_spacing:g} m apart"
    )
    print(header())
    objects = []
    for k in pairs:
        if objects and not objects[-1].done:
            print(f"{2 * k:7d} not run: every trace of {objects[-1].objects} objects timed out")
            continue
        cell = measure("objects", k, OBJECT_FRAMES, traces, repeat, args.seed, args.timeout, args.pair_spacing)
        objects.append(cell)
        print(line(objects[-1]), flush=True)

    print("\nratios (of means)")
    base = objects[0]
    for cell in objects[1:]:
        if cell.done:
            print(f"  {cell.objects:2d} objects / 2 objects: {cell.mean / base.mean:8.2f} x")
    first = durations[0]
    for cell in durations[1:]:
        print(
            f"  N = {cell.frames:6d} / N = {first.frames}: frames {cell.frames / first.frames:6.0f} x, "
            f"time {cell.mean / first.mean:7.2f} x, "
            f"time per frame {cell.mean / cell.frames / (first.mean / first.frames):5.2f} x"
        )

    print("\ntargets")
    by_objects = {c.objects: c for c in objects}
    for count, target, note in ((8, TARGET_8_OBJECTS_S, " (seed 000: timeout at 10 s)"), (16, TARGET_16_OBJECTS_S, "")):
        if count in by_objects:
            cell = by_objects[count]
            print(
                f"  {count} objects, N = {OBJECT_FRAMES}: {seconds_text(cell)}; target < {target:g} s{note}: "
                f"{verdict(cell.worst < target)}"
            )
        elif count <= 2 * max(pairs):
            print(f"  {count} objects: not run (a smaller size timed out); target < {target:g} s: FAIL")
    if long_durations:
        largest = durations[-1]
        print(
            f"  {largest.frames} frames: {seconds_text(largest)}; target < {TARGET_36K_FRAMES_S:g} s: "
            f"{verdict(largest.worst < TARGET_36K_FRAMES_S)}"
        )
        by_frames = {c.frames: c for c in durations}
        reference = by_frames[LONG_DURATIONS[0]]
        growth = (largest.mean / largest.frames) / (reference.mean / reference.frames)
        print(
            f"  linear in duration: time per frame at N = {largest.frames} is {growth:.2f} x that at N = "
            f"{reference.frames}; target <= {LINEARITY:g} x: {verdict(growth <= LINEARITY)}"
        )
    print(f"\nevery answer found was checked (see the module docstring); wall time {time.perf_counter() - start:.1f} s")
    if args.json:
        rows = {"duration": [c.row() for c in durations], "objects": [c.row() for c in objects]}
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
