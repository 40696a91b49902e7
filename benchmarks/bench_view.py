"""How long a view takes: the HTML page, a PNG and a GIF of a real recording, and the page in Chromium.

Ingests the AV2 sensor and nuScenes recordings of ../shared/real_data into a temporary dataset,
runs the SpRE ``[[:pedestrian:]]+`` over it, and for every matched recording times, as medians of
``--repeat`` runs after one warm-up: the page (trace and map read from the dataset, view built,
HTML written: what ``scenegrep show -o x.html`` does after start-up), the PNG of one frame, and
Chromium opening the page until it has drawn the first frame. The GIF (the whole trace) is timed
once. The target (issue 8): a view of a 20 s recording renders in under 2 s.

    python benchmarks/bench_view.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from timing import median_seconds  # noqa: E402
from scenegrep.dataset import open_dataset  # noqa: E402
from scenegrep.dataset.run import RunOptions  # noqa: E402
from scenegrep.view.page import view_page  # noqa: E402
from scenegrep.view.plot import picture  # noqa: E402
from scenegrep.view.sources import ResultsSource  # noqa: E402
from tests.view.conftest import chromium_driver  # noqa: E402

SHARED = REPO.parent / "shared" / "real_data"


def browser_seconds(driver, page: Path, repeat: int) -> float:
    """Median seconds from navigating to the page to its first frame drawn, in headless Chromium."""
    times = []
    for _ in range(repeat + 1):
        start = time.perf_counter()
        driver.get(page.as_uri())
        driver.execute_script("return document.body.dataset.frame")
        times.append(time.perf_counter() - start)
    return statistics.median(times[1:])


def row(source: ResultsSource, trace_id: str, page: Path, driver, repeat: int) -> str:
    """The timings of one recording's view, as a line of the table."""
    html_s = median_seconds(partial(write_page, source, trace_id, page), repeat)
    view = source.view(trace_id)
    png_s = median_seconds(partial(picture, view, "png", view.matches[0]), repeat)
    start = time.perf_counter()
    picture(view, "gif")
    gif_s = time.perf_counter() - start
    chromium_s = browser_seconds(driver, page, repeat)
    trace = view.trace
    return (
        f"{trace.name:40s} {trace.duration:5.1f} {len(trace.states):6d} {html_s:7.3f} "
        f"{page.stat().st_size / 1000:6.0f} "
        f"{png_s:6.3f} {gif_s:6.2f} {trace.n_frames:6d} {chromium_s:10.3f}"
    )


def write_page(source: ResultsSource, trace_id: str, page: Path) -> None:
    page.write_text(view_page(source.view(trace_id)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        driver = chromium_driver(str(Path(folder) / "profile"))
        dataset = open_dataset(Path(folder) / "ds", create=True)
        dataset.ingest([str(SHARED / "av2" / "sensor"), str(SHARED / "nuscenes_mini_scenarionet")], jobs=2)
        results = dataset.spre("[[:pedestrian:]]+", run=RunOptions(jobs=2))
        source = ResultsSource.of_run(dataset.path, results)
        print(
            f"{'recording':40s} {'s':>5s} {'obs':>6s} {'html s':>7s} {'KB':>6s} {'png s':>6s} {'gif s':>6s} "
            f"{'frames':>6s} {'chromium s':>10s}"
        )
        for trace_id in source.matched_trace_ids():
            print(row(source, trace_id, Path(folder) / "view.html", driver, args.repeat), flush=True)
        driver.quit()


if __name__ == "__main__":
    main()
