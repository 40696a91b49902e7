"""SpRE in the top-down space over real recordings, checked against a computation by hand."""

import json
import math

import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.spre import SearchOptions, compile_query, search

QUERY = "[E(p := [:pedestrian:])(@dist(p, [:ego:]) < 10 & <frontof>(p))]{10,}"
RECORDINGS = [
    "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl",
    "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-1094.pkl",
    "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede",
    "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76",
]


def by_hand(trace) -> list[tuple[int, int]]:
    """Maximal runs of at least 10 frames in which some pedestrian's centre is within 10 m of the
    ego's centre and ahead of it (positive along the ego's heading, 0 = +y, counter-clockwise)."""
    ids = list(trace.objects.id)
    categories = list(trace.objects.category)
    frames: dict[int, dict[str, tuple[float, float, float]]] = {}
    for f, o, x, y, h in zip(
        trace.states.frame, trace.states.object, trace.states.x, trace.states.y, trace.states.heading
    ):
        frames.setdefault(int(f), {})[ids[o]] = (float(x), float(y), float(h))
    good = []
    for f in range(trace.n_frames):
        objects = frames.get(f, {})
        ego = objects.get(trace.ego)
        hit = False
        for oid, (x, y, _) in objects.items():
            category = categories[ids.index(oid)].lower()
            if ego is None or "pedestrian" not in category:
                continue
            ex, ey, eh = ego
            ahead = (x - ex) * -math.sin(eh) + (y - ey) * math.cos(eh)
            hit = hit or (math.hypot(x - ex, y - ey) < 10 and ahead > 0)
        good.append(hit)
    runs, start = [], None
    for f, g in enumerate(good + [False]):
        if g and start is None:
            start = f
        if not g and start is not None:
            if f - start >= 10:
                runs.append((start, f))
            start = None
    return runs


@pytest.mark.parametrize("relative", RECORDINGS)
def test_pedestrian_ahead_of_the_ego(real_data, relative):
    trace = readers.read_trace(real_data / relative)
    found = [(m.start, m.end) for m in search(compile_query(QUERY), trace, SearchOptions(space="topdown"))]
    expected = by_hand(trace)
    assert found == expected
    assert found, "each of these recordings has such a stretch"


def test_command_line_on_a_real_recording(real_data, capsys):
    path = real_data / RECORDINGS[2]
    assert main(["spre", "--space", "topdown", "--json", QUERY, str(path)]) == 0
    (line,) = capsys.readouterr().out.splitlines()
    record = json.loads(line)
    assert (record["start_frame"], record["end_frame"]) == (146, 155)  # as by_hand finds: frames 146..155
