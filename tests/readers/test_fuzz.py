"""Fuzz suite: every reader, on mutated real files, gives a result or a one-line user error.

Each case copies a real input (../shared/real_data, ../shared/conformance, examples/) into a
fresh folder, mutates one of its files (:mod:`tests.readers.mutations`) and runs
``scenegrep info`` on it in the sandbox (:mod:`tests.readers.sandbox`: 2 GB of address space,
60 s). The outcome must be exit 0, or exit 2 with exactly one line on stderr naming the input;
never a traceback, a signal (the time limit, a crash of the C parser) or another exit code.

A few examples per reader run by default (derandomised: the same ones every run); the slow test,
which the full suite runs beside them, tries twice as many random ones more, three times as many
in all, and OpenDRIVE's (Scenic takes seconds per map), which has no default run, three times
its few; ``SCENEGREP_FUZZ_EXAMPLES`` overrides both.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import REPO, SHARED
from tests.readers import mutations as m

pytestmark = pytest.mark.real_data

JSON = (*m.BYTE_MUTATIONS, m.json_document, m.json_document, m.json_document)
PARQUET = (m.truncate, m.flip, m.parquet_table, m.parquet_table, m.parquet_table)
FEATHER = (m.truncate, m.flip, m.feather_table, m.feather_table, m.feather_table)


@dataclass(frozen=True)
class Case:
    """A reader's fuzz case: files copied from ``sources`` into a folder, the argument given to
    ``scenegrep info`` (relative to that folder), and the mutations of each mutable file."""

    name: str
    sources: tuple[Path, ...]
    target: str
    mutable: dict[str, tuple[m.Mutation, ...]]
    options: tuple[str, ...] = ()
    examples: int = 6


REAL = SHARED / "real_data"
SENSOR = REAL / "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
FORECAST = REAL / "av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151"
SENSOR_MAP = "map/log_map_archive_7fab2350-7eaf-3b7e-a39d-6937a4c1bede____PIT_city_47896.json"
SAMPLE = REPO / "examples/sample/s3_pass_pedestrian-000.parquet"

CASES = [
    Case("strem-json", (SHARED / "conformance/strem/data/multidoc.json",), "multidoc.json", {"multidoc.json": JSON}),
    Case("scenegrep-json", (), "trace.json", {"trace.json": JSON}, ("--no-map",)),
    Case("scenegrep-parquet", (SAMPLE,), SAMPLE.name, {SAMPLE.name: PARQUET}, ("--no-map",), examples=4),
    Case(
        "av2-sensor",
        (SENSOR,),
        SENSOR.name,
        {f"{SENSOR.name}/annotations.feather": FEATHER, f"{SENSOR.name}/city_SE3_egovehicle.feather": FEATHER},
        ("--no-map",),
        examples=3,
    ),
    Case(
        "av2-forecasting",
        (FORECAST,),
        FORECAST.name,
        {f"{FORECAST.name}/scenario_{FORECAST.name}.parquet": PARQUET},
        ("--no-map",),
        examples=3,
    ),
    Case("scenegrep-map-parquet", (), "map.parquet", {"map.parquet": PARQUET}, examples=2),
    Case(
        "av2-map",
        (FORECAST / f"log_map_archive_{FORECAST.name}.json",),
        f"log_map_archive_{FORECAST.name}.json",
        {f"log_map_archive_{FORECAST.name}.json": JSON},
    ),
    Case(
        "scenarionet",
        (REAL / "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0757.pkl",),
        "sd_nuscenes_v1.0-mini_scene-0757.pkl",
        {"sd_nuscenes_v1.0-mini_scene-0757.pkl": (m.truncate, m.flip, *(m.pickle_document,) * 4)},
    ),
    Case(
        "waymo-tfrecord",
        (REAL / "waymo_womd/motion_data_one_scenario.tfrecord",),
        "motion_data_one_scenario.tfrecord",
        {"motion_data_one_scenario.tfrecord": (m.truncate, m.flip, m.tfrecord_length, *(m.tfrecord_payload,) * 3)},
    ),
    Case(
        "commonroad",
        (REAL / "commonroad_ngsim/USA_US101-3_3_T-1.xml",),
        "USA_US101-3_3_T-1.xml",
        {"USA_US101-3_3_T-1.xml": (*m.BYTE_MUTATIONS, *(m.xml_document,) * 3)},
    ),
    Case("lanelet2", (), "map.osm", {"map.osm": (*m.BYTE_MUTATIONS, *(m.xml_document,) * 3)}, examples=3),
    Case(
        "trace-folder",
        (SAMPLE, REPO / "examples/sample/s3_pass_pedestrian-001.parquet"),
        ".",
        {SAMPLE.name: PARQUET},
        ("--no-map",),
        examples=2,
    ),
]
"""Every reader but OpenDRIVE (below: Scenic takes seconds per map)."""

OPENDRIVE = Case(
    "opendrive",
    (SHARED / "maps/Town01.xodr",),
    "Town01.xodr",
    {"Town01.xodr": (m.truncate, m.xml_document)},
    examples=1,
)


def _write_json_trace(folder: Path) -> None:
    """The seed of the scenegrep-json case: the first 20 frames of a sample trace."""
    from scenegrep.readers.trace_parquet import read_trace
    from scenegrep.writers.trace_json import write_trace_json

    write_trace_json(read_trace(SAMPLE).slice_frames(0, 20), folder / "trace.json")


def _write_map_parquet(folder: Path) -> None:
    """The seed of the scenegrep-map-parquet case: the AV2 forecasting scenario's map."""
    from scenegrep.readers.av2_map import read_map
    from scenegrep.writers import write_map_parquet

    write_map_parquet(read_map(FORECAST / f"log_map_archive_{FORECAST.name}.json"), folder / "map.parquet")


def _write_lanelet2(folder: Path) -> None:
    """The seed of the lanelet2 case: the AV2 sensor log's map written as a Lanelet2 map."""
    from scenegrep.writers.lanelet2 import write_av2_lanelet2

    write_av2_lanelet2(json.loads((SENSOR / SENSOR_MAP).read_bytes()), folder / "map.osm")


SEEDS = {
    "scenegrep-json": _write_json_trace,
    "scenegrep-map-parquet": _write_map_parquet,
    "lanelet2": _write_lanelet2,
}
"""Cases whose seed file is written from a real input rather than copied."""


def _prepare(case: Case, folder: Path, seeds: Path) -> None:
    """Copy the case's inputs into ``folder``; written seeds are made once in ``seeds``."""
    if case.name in SEEDS:
        written = seeds / case.name
        if not written.exists():
            written.mkdir()
            SEEDS[case.name](written)
        shutil.copytree(written, folder, dirs_exist_ok=True)
    for source in case.sources:
        copy = shutil.copytree if source.is_dir() else shutil.copy
        copy(source, folder / source.name)
    for path in folder.rglob("*"):
        path.chmod(0o755 if path.is_dir() else 0o644)


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory) -> Iterator[Callable[[list[str]], dict]]:
    """Run ``scenegrep ARGS`` in the sandbox; returns the outcome (see tests.readers.sandbox)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), SCENEGREP_CACHE=str(tmp_path_factory.mktemp("cache")))
    process = subprocess.Popen(
        [sys.executable, "-m", "tests.readers.sandbox"],
        cwd=REPO,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )

    def run(argv: list[str]) -> dict:
        process.stdin.write(json.dumps(argv) + "\n")
        process.stdin.flush()
        return json.loads(process.stdout.readline())

    yield run
    process.stdin.close()
    process.wait(timeout=30)


def check_outcome(outcome: dict, name: str) -> None:
    """A result (exit 0) or one line naming the input (exit 2); over a folder (``name`` empty) also
    one line naming the bad file while the others are summarised (exit 3); nothing else."""
    text = outcome["stderr"]
    assert outcome["signal"] is None, f"killed by signal {outcome['signal']} after {outcome['seconds']:.1f} s"
    assert "Traceback" not in text, text
    assert outcome["exit"] in ((0, 2) if name else (0, 2, 3)), (outcome["exit"], text)
    if outcome["exit"] == 3:
        assert text.count("\n") == 1 and text.startswith("scenegrep: failed: "), text
    if outcome["exit"] == 2:
        assert text.count("\n") == 1 and text.startswith("scenegrep: error: "), text
        assert name in text, text


def _examples(case: Case, slow: bool) -> int:
    """The number of examples of a case (see the module docstring)."""
    default = case.examples * ((2 if case in CASES else 3) if slow else 1)
    return int(os.environ.get("SCENEGREP_FUZZ_EXAMPLES", default))


def fuzz(case: Case, sandbox: Callable[[list[str]], dict], tmp_path_factory, slow: bool) -> None:
    """Run the case's examples: copy, mutate one file, run ``scenegrep info``, check the outcome."""
    if not all(source.exists() for source in case.sources):
        pytest.skip("real data or maps are absent")

    @settings(
        max_examples=_examples(case, slow), suppress_health_check=list(HealthCheck), database=None, derandomize=not slow
    )
    @given(seed=st.integers(0, 2**32 - 1))
    def example(seed: int) -> None:
        rng = random.Random(seed)
        folder = tmp_path_factory.mktemp(case.name)
        _prepare(case, folder, tmp_path_factory.getbasetemp())
        mutable = rng.choice(sorted(case.mutable))
        m.mutate_file(folder / mutable, case.mutable[mutable], rng)
        target = folder / case.target
        check_outcome(sandbox(["info", *case.options, str(target)]), target.name if case.target != "." else "")
        shutil.rmtree(folder)

    example()


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_reader_fuzz(case, sandbox, tmp_path_factory):
    fuzz(case, sandbox, tmp_path_factory, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("case", [*CASES, OPENDRIVE], ids=[c.name for c in [*CASES, OPENDRIVE]])
def test_reader_fuzz_long(case, sandbox, tmp_path_factory):
    fuzz(case, sandbox, tmp_path_factory, slow=True)
